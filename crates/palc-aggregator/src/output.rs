//! Writing output files so that nothing is lost: the one writer of the experience
//! store, the `palc` binary and the evaluation.
//!
//! [`write_with`] writes a regular file through a temporary file in the same
//! directory (named after the target and this process's id), flushes it and checks
//! the flush (a full disk is an error, not a short file), syncs it to disk, renames
//! it over the target and syncs the directory. So the target holds either its old
//! bytes or all of the new ones, whatever fails and whenever the process is killed.
//! An existing target keeps its permissions (and, where allowed, its owner); a
//! symbolic link is followed, so the file it points to is replaced and the link
//! stays. A target that exists and is not a regular file (`/dev/stdout`,
//! `/dev/full`, a pipe) is written in place, with the flush checked. Temporary
//! files left behind by processes that were killed are removed on the next write
//! into the same directory (on Linux, where a process's liveness can be read from
//! `/proc`).
//!
//! [`Staging`] is the same idea for a directory of files: they are written into a
//! temporary directory next to the destination, which takes the destination's
//! place in one atomic exchange at the end (`renameat2` with `RENAME_EXCHANGE`,
//! through `rustix`), so the destination holds either all of the previous files or
//! all of the new ones.
//!
//! [`AppendLog`] is the one exception to whole-file writes: a log that only grows
//! (a driving study's record), opened for appending, flushed and synced to disk
//! at the points the caller chooses, never truncated or rewritten.
//!
//! The temporary file itself comes from `tempfile` (unique name, removed on every
//! error path); this module only adds what `tempfile` leaves to the caller.

use std::ffi::{OsStr, OsString};
use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Symbolic links followed before giving up (the limit of Linux's `open`).
const MAX_SYMLINK_HOPS: usize = 40;

/// An output file could not be written; the previous file, if any, is unchanged.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {}: {error}", path.display())]
pub struct OutputError {
    /// The file that was to be written (as given, before following links).
    pub path: PathBuf,
    /// The cause; in the message, so not repeated as a `source`.
    pub error: io::Error,
}

/// Writes `bytes` to `path` as [`write_with`] does.
///
/// # Errors
/// [`OutputError`] naming `path`; the previous file is left as it was.
pub fn write(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    write_with(path, |w| w.write_all(bytes))
}

/// Writes the file at `path` with `fill`, safely (see the module's documentation).
/// `fill` writes into a buffered writer; its error, or any error of the flush, the
/// sync or the rename, leaves the previous file in place.
///
/// # Errors
/// [`OutputError`] naming `path`.
pub fn write_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), OutputError> {
    write_inner(path, fill).map_err(|error| OutputError {
        path: path.to_owned(),
        error,
    })
}

/// Checks, before any work, that [`write()`] could write `path`: it is not a
/// directory, its directory exists, and a file can be created there (a temporary
/// one, removed at once). A command calls it for each output it was given, so that
/// a bad `--out` is refused in a second rather than after a run of minutes.
///
/// # Errors
/// [`OutputError`] naming `path` and what is wrong.
pub fn check_writable(path: &Path) -> Result<(), OutputError> {
    check_inner(path).map_err(|error| OutputError {
        path: path.to_owned(),
        error,
    })
}

fn check_inner(path: &Path) -> io::Result<()> {
    let target = resolve_symlinks(path)?;
    match fs::metadata(&target) {
        Ok(metadata) if metadata.is_dir() => {
            return Err(io::Error::new(
                io::ErrorKind::IsADirectory,
                "the path is a directory, not a file",
            ));
        }
        // A device or a pipe is written in place.
        Ok(metadata) if !metadata.is_file() => return Ok(()),
        Ok(_) => {}
        Err(e) if e.kind() == io::ErrorKind::NotFound => {}
        Err(e) => return Err(e),
    }
    if target.file_name().is_none() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "the path names no file",
        ));
    }
    let directory = parent_directory(&target);
    match fs::metadata(&directory) {
        Ok(metadata) if metadata.is_dir() => {}
        Ok(_) => {
            return Err(io::Error::new(
                io::ErrorKind::NotADirectory,
                format!("{} is not a directory", directory.display()),
            ));
        }
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Err(io::Error::new(
                io::ErrorKind::NotFound,
                format!("the directory {} does not exist", directory.display()),
            ));
        }
        Err(e) => return Err(e),
    }
    tempfile::Builder::new()
        .prefix(".palc-check-")
        .tempfile_in(&directory)
        .map(drop)
}

fn write_inner(path: &Path, fill: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> io::Result<()> {
    let target = resolve_symlinks(path)?;
    let existing = match fs::metadata(&target) {
        Ok(metadata) => Some(metadata),
        Err(e) if e.kind() == io::ErrorKind::NotFound => None,
        Err(e) => return Err(e),
    };
    if let Some(metadata) = &existing {
        if metadata.is_dir() {
            return Err(io::Error::new(
                io::ErrorKind::IsADirectory,
                "the path is a directory, not a file",
            ));
        }
        if !metadata.is_file() {
            // A device or a pipe: it cannot be replaced, only written.
            let mut writer = BufWriter::new(fs::OpenOptions::new().write(true).open(&target)?);
            fill(&mut writer)?;
            return writer.flush();
        }
    }
    let file_name = target
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path names no file"))?;
    let directory = parent_directory(&target);
    remove_stale_temporaries(&directory, file_name);
    let prefix = temporary_prefix(file_name);
    let suffix = format!(".tmp-{}", std::process::id());
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(&suffix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // The mode `File::create` would give (0666 less the umask), for a new file.
        builder.permissions(fs::Permissions::from_mode(0o666));
    }
    let mut temporary = builder.tempfile_in(&directory)?;
    {
        let mut writer = BufWriter::new(temporary.as_file_mut());
        fill(&mut writer)?;
        writer.flush()?;
    }
    if let Some(metadata) = &existing {
        keep_owner_and_permissions(temporary.as_file(), metadata)?;
    }
    temporary.as_file().sync_all()?;
    temporary.persist(&target).map_err(|e| e.error)?;
    sync_directory(&directory)
}

/// The directory that holds `path` (`.` for a bare file name).
fn parent_directory(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => PathBuf::from("."),
    }
}

/// The most bytes of a target's name that its temporaries' names repeat: with the
/// dots, the random part, `previous` and `.tmp-<pid>` they stay within the 255
/// bytes a name may have on common file systems, so a target named up to that
/// limit can be written.
const MAX_NAME_IN_TEMPORARY: usize = 200;

/// `.name.` : every temporary of `name` starts with it (a hidden file); a name
/// longer than [`MAX_NAME_IN_TEMPORARY`] bytes is cut there (at a character
/// boundary when it is UTF-8).
fn temporary_prefix(file_name: &OsStr) -> OsString {
    let mut prefix = OsString::from(".");
    prefix.push(shortened(file_name));
    prefix.push(".");
    prefix
}

/// `name` cut to at most [`MAX_NAME_IN_TEMPORARY`] bytes.
fn shortened(name: &OsStr) -> OsString {
    if name.len() <= MAX_NAME_IN_TEMPORARY {
        return name.to_owned();
    }
    if let Some(text) = name.to_str() {
        let mut end = MAX_NAME_IN_TEMPORARY;
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        return OsString::from(&text[..end]);
    }
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        OsStr::from_bytes(&name.as_bytes()[..MAX_NAME_IN_TEMPORARY]).to_owned()
    }
    #[cfg(not(unix))]
    {
        OsString::from(name.to_string_lossy().chars().take(50).collect::<String>())
    }
}

/// Follows symbolic links from `path` to the file that would be written.
fn resolve_symlinks(path: &Path) -> io::Result<PathBuf> {
    let mut current = path.to_owned();
    for _ in 0..MAX_SYMLINK_HOPS {
        match fs::symlink_metadata(&current) {
            Ok(metadata) if metadata.file_type().is_symlink() => {
                let link = fs::read_link(&current)?;
                current = parent_directory(&current).join(link);
            }
            Ok(_) => return Ok(current),
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(current),
            Err(e) => return Err(e),
        }
    }
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("more than {MAX_SYMLINK_HOPS} symbolic links"),
    ))
}

#[cfg(unix)]
fn keep_owner_and_permissions(file: &fs::File, metadata: &fs::Metadata) -> io::Result<()> {
    use std::os::unix::fs::MetadataExt;
    let own = file.metadata()?;
    if (own.uid(), own.gid()) != (metadata.uid(), metadata.gid()) {
        // Only a privileged process may give a file away; anyone else keeps the
        // file as their own, as an editor would.
        let _ = std::os::unix::fs::fchown(file, Some(metadata.uid()), Some(metadata.gid()));
    }
    file.set_permissions(metadata.permissions())
}

#[cfg(not(unix))]
fn keep_owner_and_permissions(file: &fs::File, metadata: &fs::Metadata) -> io::Result<()> {
    file.set_permissions(metadata.permissions())
}

#[cfg(unix)]
fn sync_directory(directory: &Path) -> io::Result<()> {
    fs::File::open(directory)?.sync_all()
}

#[cfg(not(unix))]
fn sync_directory(_directory: &Path) -> io::Result<()> {
    Ok(())
}

/// Whether the process `pid` is known to have ended (never true where liveness
/// cannot be read, so nothing is removed there).
fn process_has_ended(pid: u32) -> bool {
    let proc = Path::new("/proc");
    proc.join("self").exists() && !proc.join(pid.to_string()).exists()
}

/// The id of the process that made `name`, a temporary of `prefix`, if it is one.
fn temporary_owner(name: &OsStr, prefix: &OsStr) -> Option<u32> {
    let name = name.to_str()?;
    let rest = name.strip_prefix(prefix.to_str()?)?;
    let (_, pid) = rest.rsplit_once(".tmp-")?;
    pid.parse().ok()
}

/// Removes the temporaries of `file_name` in `directory` whose process has ended.
/// Best effort: a temporary that cannot be removed is left, and the write goes on.
fn remove_stale_temporaries(directory: &Path, file_name: &OsStr) {
    let prefix = temporary_prefix(file_name);
    let Ok(entries) = fs::read_dir(directory) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = temporary_owner(&name, &prefix) else {
            continue;
        };
        if pid != std::process::id() && process_has_ended(pid) {
            let path = entry.path();
            let _ = if path.is_dir() {
                fs::remove_dir_all(&path)
            } else {
                fs::remove_file(&path)
            };
        }
    }
}

/// A set of output files written into a temporary directory next to their
/// destination, which takes the destination's place only in [`Staging::commit`].
/// Dropped without a commit (an error, a panic), it removes itself and the
/// destination is untouched.
#[derive(Debug)]
pub struct Staging {
    directory: tempfile::TempDir,
    /// The destination as given.
    destination: PathBuf,
    /// The destination with symbolic links followed: the directory replaced.
    target: PathBuf,
}

/// A step of [`Staging::commit_with`] that changes the file system, announced
/// before it is taken.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum CommitStep {
    /// An entry of the previous destination that this run did not write (named
    /// here) is hard-linked (a directory: its tree) into the staging directory;
    /// the destination is not touched.
    Carry(OsString),
    /// The staging directory and the previous destination trade places in one
    /// atomic exchange.
    Exchange,
    /// Where no exchange is offered: the previous destination is renamed aside.
    MoveAside,
    /// The staging directory is renamed to the destination (a destination that
    /// did not exist, or after [`CommitStep::MoveAside`]).
    MoveIn,
    /// The previous results, no longer at the destination, are removed.
    RemovePrevious,
}

/// The middle of the hidden name under which the fallback keeps the previous
/// destination while the new one is renamed in.
const PREVIOUS: &str = "previous";

impl Staging {
    /// Creates the staging directory next to `destination` (which need not exist;
    /// a symbolic link is followed), after putting back a previous destination that
    /// a killed commit left aside and removing the staging directories of processes
    /// that have ended.
    ///
    /// # Errors
    /// [`OutputError`] naming `destination`, also when it exists and is not a
    /// directory.
    pub fn new(destination: &Path) -> Result<Staging, OutputError> {
        let error = |error| OutputError {
            path: destination.to_owned(),
            error,
        };
        let mut target = resolve_symlinks(destination).map_err(error)?;
        match fs::metadata(&target) {
            Ok(metadata) if !metadata.is_dir() => {
                return Err(error(io::Error::new(
                    io::ErrorKind::NotADirectory,
                    "it exists and is not a directory",
                )));
            }
            Ok(_) => {}
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            Err(e) => return Err(error(e)),
        }
        if target.file_name().is_none() {
            // `.`, `..` or `/`: the directory's own name.
            target = fs::canonicalize(&target).map_err(error)?;
        }
        let name = target.file_name().map(OsStr::to_owned).ok_or_else(|| {
            error(io::Error::new(
                io::ErrorKind::InvalidInput,
                "the path names no directory",
            ))
        })?;
        let parent = parent_directory(&target);
        fs::create_dir_all(&parent).map_err(error)?;
        restore_previous(&parent, &name, &target).map_err(error)?;
        remove_stale_temporaries(&parent, &name);
        let prefix = temporary_prefix(&name);
        let suffix = format!(".tmp-{}", std::process::id());
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(&suffix);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            // The mode `fs::create_dir` would give (0777 less the umask).
            builder.permissions(fs::Permissions::from_mode(0o777));
        }
        let directory = builder.tempdir_in(&parent).map_err(error)?;
        Ok(Staging {
            directory,
            destination: destination.to_owned(),
            target,
        })
    }

    /// Where to write the files.
    pub fn path(&self) -> &Path {
        self.directory.path()
    }

    /// The directory the files will be moved to.
    pub fn destination(&self) -> &Path {
        &self.destination
    }

    /// Puts the staging directory in the destination's place, as
    /// [`Staging::commit_with`] does.
    ///
    /// # Errors
    /// [`OutputError`] naming the path that could not be carried, moved or synced.
    pub fn commit(self, obsolete: &[&str]) -> Result<(), OutputError> {
        self.commit_with(obsolete, |_| Ok(()))
    }

    /// Puts the staging directory in the destination's place in one step, so that
    /// the destination holds either all of its previous entries or all of the new
    /// ones, whatever fails and whenever the process is killed.
    ///
    /// First the entries of the previous destination that this run did not write,
    /// except the `obsolete` ones (files of an earlier run that this one no longer
    /// makes), are hard-linked into the staging directory (a directory as a tree of
    /// links, a file that cannot be linked copied), without touching the
    /// destination: the user's own files and nested results stay. The staging
    /// directory takes the previous destination's permissions and is synced. Then,
    /// on Linux and macOS, one `renameat2(RENAME_EXCHANGE)` (macOS: `RENAME_SWAP`)
    /// trades the two directories; the previous one, now at the staging name, is
    /// removed. Where the system or the file system offers no exchange, the previous
    /// destination is renamed aside, the staging directory renamed in and the
    /// previous one removed: a kill between those two renames leaves no destination
    /// but the previous one under a hidden name beside it, which the next
    /// [`Staging::new`] for the same destination puts back. A destination that does
    /// not exist is created by one rename.
    ///
    /// `before` is called before every step that changes the file system; an error
    /// it returns stops the commit there as the failure of that step would (a test
    /// hook: faults between every two steps; [`io::ErrorKind::Unsupported`] at
    /// [`CommitStep::Exchange`] stands for a file system without the exchange). The
    /// failure of [`CommitStep::RemovePrevious`] is no error: the results are in
    /// place, and the next commit removes the leftover.
    ///
    /// # Errors
    /// [`OutputError`] naming the path that could not be carried, moved or synced;
    /// the destination then holds its previous entries.
    pub fn commit_with(
        self,
        obsolete: &[&str],
        mut before: impl FnMut(&CommitStep) -> io::Result<()>,
    ) -> Result<(), OutputError> {
        let error = |path: &Path| {
            let path = path.to_owned();
            move |error| OutputError { path, error }
        };
        let staged = self.directory.path().to_owned();
        let target = self.target.clone();
        let previous = match fs::metadata(&target) {
            Ok(metadata) if metadata.is_dir() => Some(metadata),
            Ok(_) => {
                return Err(error(&self.destination)(io::Error::new(
                    io::ErrorKind::NotADirectory,
                    "it exists and is not a directory",
                )));
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => None,
            Err(e) => return Err(error(&self.destination)(e)),
        };
        if let Some(metadata) = &previous {
            let mut entries: Vec<fs::DirEntry> = fs::read_dir(&target)
                .map_err(error(&target))?
                .collect::<Result<_, _>>()
                .map_err(error(&target))?;
            entries.sort_by_key(fs::DirEntry::file_name);
            for entry in entries {
                let name = entry.file_name();
                let into = staged.join(&name);
                let written = fs::symlink_metadata(&into).is_ok();
                if written || obsolete.iter().any(|o| OsStr::new(o) == name) {
                    continue;
                }
                before(&CommitStep::Carry(name))
                    .and_then(|()| carry(&entry.path(), &into))
                    .map_err(error(&entry.path()))?;
            }
            fs::set_permissions(&staged, metadata.permissions()).map_err(error(&staged))?;
        }
        sync_directory(&staged).map_err(error(&staged))?;
        let parent = parent_directory(&target);
        if previous.is_none() {
            before(&CommitStep::MoveIn)
                .and_then(|()| fs::rename(&staged, &target))
                .map_err(error(&self.destination))?;
            let _ = self.directory.keep();
            return sync_directory(&parent).map_err(error(&parent));
        }
        match before(&CommitStep::Exchange).and_then(|()| exchange(&staged, &target)) {
            Ok(()) => {
                sync_directory(&parent).map_err(error(&parent))?;
                let old = self.directory.keep();
                if before(&CommitStep::RemovePrevious).is_ok() {
                    let _ = fs::remove_dir_all(old);
                }
                return Ok(());
            }
            Err(e) if e.kind() == io::ErrorKind::Unsupported => {}
            Err(e) => return Err(error(&self.destination)(e)),
        }
        // No exchange: aside, in, and back if the second rename fails.
        let name = target.file_name().unwrap_or_default();
        let mut aside_name = temporary_prefix(name);
        aside_name.push(format!("{PREVIOUS}.tmp-{}", std::process::id()));
        let aside = parent.join(aside_name);
        before(&CommitStep::MoveAside)
            .and_then(|()| fs::rename(&target, &aside))
            .map_err(error(&self.destination))?;
        if let Err(e) = before(&CommitStep::MoveIn).and_then(|()| fs::rename(&staged, &target)) {
            let _ = fs::rename(&aside, &target);
            return Err(error(&self.destination)(e));
        }
        let _ = self.directory.keep();
        sync_directory(&parent).map_err(error(&parent))?;
        if before(&CommitStep::RemovePrevious).is_ok() {
            let _ = fs::remove_dir_all(aside);
        }
        Ok(())
    }
}

/// Trades the directories `a` and `b` in one atomic step; `Unsupported` where the
/// system or the file system cannot.
#[cfg(any(target_os = "linux", target_os = "android", target_vendor = "apple"))]
fn exchange(a: &Path, b: &Path) -> io::Result<()> {
    use rustix::fs::{CWD, RenameFlags, renameat_with};
    use rustix::io::Errno;
    match renameat_with(CWD, a, CWD, b, RenameFlags::EXCHANGE) {
        Ok(()) => Ok(()),
        // An old kernel, or a file system without the flag.
        Err(e) if e == Errno::INVAL || e == Errno::NOSYS || e == Errno::OPNOTSUPP => Err(
            io::Error::new(io::ErrorKind::Unsupported, io::Error::from(e)),
        ),
        Err(e) => Err(e.into()),
    }
}

#[cfg(not(any(target_os = "linux", target_os = "android", target_vendor = "apple")))]
fn exchange(_a: &Path, _b: &Path) -> io::Result<()> {
    Err(io::Error::from(io::ErrorKind::Unsupported))
}

/// Recreates `from` at `to` without touching `from`: a file as a hard link (a copy
/// where no link can be made), a directory as a tree of them, a symbolic link as
/// the same link.
fn carry(from: &Path, to: &Path) -> io::Result<()> {
    let metadata = fs::symlink_metadata(from)?;
    let kind = metadata.file_type();
    if kind.is_dir() {
        fs::create_dir(to)?;
        for entry in fs::read_dir(from)? {
            let entry = entry?;
            carry(&entry.path(), &to.join(entry.file_name()))?;
        }
        fs::set_permissions(to, metadata.permissions())
    } else if kind.is_symlink() {
        symlink(&fs::read_link(from)?, to)
    } else {
        fs::hard_link(from, to).or_else(|_| fs::copy(from, to).map(|_| ()))
    }
}

#[cfg(unix)]
fn symlink(link: &Path, at: &Path) -> io::Result<()> {
    std::os::unix::fs::symlink(link, at)
}

#[cfg(not(unix))]
fn symlink(link: &Path, at: &Path) -> io::Result<()> {
    // The file the link points to, copied.
    fs::copy(parent_directory(at).join(link), at).map(|_| ())
}

/// Renames back a previous destination that a commit killed between its two
/// renames left aside (only when `target` is missing, and only one of a process
/// that has ended).
fn restore_previous(parent: &Path, name: &OsStr, target: &Path) -> io::Result<()> {
    if fs::symlink_metadata(target).is_ok() {
        return Ok(());
    }
    let prefix = temporary_prefix(name);
    let Ok(entries) = fs::read_dir(parent) else {
        return Ok(());
    };
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(pid) = temporary_owner(&file_name, &prefix) else {
            continue;
        };
        let aside = file_name.to_str().and_then(|n| {
            n.strip_prefix(prefix.to_str()?)?
                .strip_suffix(&format!(".tmp-{pid}"))
        });
        if aside == Some(PREVIOUS) && pid != std::process::id() && process_has_ended(pid) {
            return fs::rename(entry.path(), target);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_name_is_cut_in_its_temporaries_at_a_character_boundary() {
        let long = "é".repeat(120);
        let prefix = temporary_prefix(OsStr::new(&long));
        let text = prefix.to_str().unwrap();
        assert!(text.len() <= MAX_NAME_IN_TEMPORARY + 2, "{}", text.len());
        assert!(long.starts_with(&text[1..text.len() - 1]));
        assert_eq!(temporary_prefix(OsStr::new("e.json")), ".e.json.");
    }

    #[test]
    fn the_owner_of_a_temporary_is_read_from_its_name() {
        let prefix = temporary_prefix(OsStr::new("e.json"));
        assert_eq!(
            temporary_owner(OsStr::new(".e.json.Ab12cd.tmp-4321"), &prefix),
            Some(4321)
        );
        assert_eq!(
            temporary_owner(OsStr::new(".e.json.x.tmp-nope"), &prefix),
            None
        );
        assert_eq!(
            temporary_owner(OsStr::new(".f.json.Ab12cd.tmp-4321"), &prefix),
            None
        );
        assert_eq!(temporary_owner(OsStr::new("e.json"), &prefix), None);
    }
}

/// A file that only grows by appended bytes, synced to disk when asked.
#[derive(Debug)]
pub struct AppendLog {
    path: PathBuf,
    file: BufWriter<fs::File>,
}

impl AppendLog {
    /// Opens `path` for appending: a new file when `create` (an existing one is
    /// an error, so no log is appended to by mistake), else an existing one.
    ///
    /// # Errors
    /// [`OutputError`] naming `path`.
    pub fn open(path: &Path, create: bool) -> Result<Self, OutputError> {
        let mut options = fs::OpenOptions::new();
        options.append(true);
        if create {
            options.create_new(true);
        }
        let file = options.open(path).map_err(|error| OutputError {
            path: path.to_path_buf(),
            error,
        })?;
        Ok(Self {
            path: path.to_path_buf(),
            file: BufWriter::new(file),
        })
    }

    /// Appends `bytes` (buffered).
    ///
    /// # Errors
    /// [`OutputError`] naming the file.
    pub fn append(&mut self, bytes: &[u8]) -> Result<(), OutputError> {
        self.file.write_all(bytes).map_err(|error| OutputError {
            path: self.path.clone(),
            error,
        })
    }

    /// Flushes the buffer, checks the flush and syncs the file's data to disk.
    ///
    /// # Errors
    /// [`OutputError`] naming the file.
    pub fn sync(&mut self) -> Result<(), OutputError> {
        let error = |error| OutputError {
            path: self.path.clone(),
            error,
        };
        self.file.flush().map_err(error)?;
        self.file.get_ref().sync_data().map_err(error)
    }
}
