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
//! [`Staging`] is the same idea for a set of files: they are written into a
//! temporary directory next to the destination, which is moved into place file by
//! file at the end, so a failed run leaves the previous files as they were.
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

/// `.name.` : every temporary of `name` starts with it (a hidden file).
fn temporary_prefix(file_name: &OsStr) -> OsString {
    let mut prefix = OsString::from(".");
    prefix.push(file_name);
    prefix.push(".");
    prefix
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
/// destination and moved into place only by [`Staging::commit`]. Dropped without a
/// commit (an error, a panic), it removes itself and the destination is untouched.
#[derive(Debug)]
pub struct Staging {
    directory: tempfile::TempDir,
    destination: PathBuf,
}

impl Staging {
    /// Creates the staging directory next to `destination` (which need not exist),
    /// after removing the staging directories of processes that have ended.
    ///
    /// # Errors
    /// [`OutputError`] naming `destination`.
    pub fn new(destination: &Path) -> Result<Staging, OutputError> {
        let error = |error| OutputError {
            path: destination.to_owned(),
            error,
        };
        let name = destination
            .file_name()
            .filter(|n| *n != "." && *n != "..")
            .map(OsStr::to_owned)
            .or_else(|| {
                fs::canonicalize(destination)
                    .ok()
                    .and_then(|p| p.file_name().map(OsStr::to_owned))
            })
            .unwrap_or_else(|| OsString::from("out"));
        let parent = match fs::canonicalize(destination) {
            Ok(full) => parent_directory(&full),
            Err(_) => parent_directory(destination),
        };
        fs::create_dir_all(&parent).map_err(error)?;
        remove_stale_temporaries(&parent, &name);
        let prefix = temporary_prefix(&name);
        let suffix = format!(".tmp-{}", std::process::id());
        let directory = tempfile::Builder::new()
            .prefix(&prefix)
            .suffix(&suffix)
            .tempdir_in(&parent)
            .map_err(error)?;
        Ok(Staging {
            directory,
            destination: destination.to_owned(),
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

    /// Moves every file of the staging directory into the destination (created if
    /// need be), each by one rename that replaces a file of the same name, the files
    /// named in `last` after all others (e.g. a report after what it describes); then
    /// removes the `obsolete` files of an earlier run that this one did not write, and
    /// syncs the destination. Other files in the destination are left alone.
    ///
    /// # Errors
    /// [`OutputError`] naming the file that could not be moved.
    pub fn commit(self, last: &[&str], obsolete: &[&str]) -> Result<(), OutputError> {
        let destination = self.destination.clone();
        let error = |path: &Path| {
            let path = path.to_owned();
            move |error| OutputError { path, error }
        };
        fs::create_dir_all(&destination).map_err(error(&destination))?;
        let mut entries: Vec<fs::DirEntry> = fs::read_dir(self.path())
            .map_err(error(self.path()))?
            .collect::<Result<_, _>>()
            .map_err(error(self.path()))?;
        entries.sort_by_key(fs::DirEntry::file_name);
        let written: Vec<OsString> = entries.iter().map(fs::DirEntry::file_name).collect();
        entries.sort_by_key(|e| last.iter().position(|l| e.file_name() == *l));
        for entry in &entries {
            let target = destination.join(entry.file_name());
            fs::File::open(entry.path())
                .and_then(|f| f.sync_all())
                .map_err(error(&target))?;
            fs::rename(entry.path(), &target).map_err(error(&target))?;
        }
        for name in obsolete {
            if !written.iter().any(|w| w == name) {
                let path = destination.join(name);
                match fs::remove_file(&path) {
                    Err(e) if e.kind() != io::ErrorKind::NotFound => {
                        return Err(error(&path)(e));
                    }
                    _ => {}
                }
            }
        }
        sync_directory(&destination).map_err(error(&destination))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
