//! The output writer: every failure leaves the previous file, permissions and
//! links are kept, temporaries of dead processes are removed; a staged directory
//! replaces the previous one whole, whatever fails between its steps.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use palc_aggregator::output::{self, CommitStep, Staging};

/// A fresh directory under the system's temporary directory, one per call.
fn scratch() -> PathBuf {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "palc-output-test-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn names(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn a_failed_write_leaves_the_previous_file_and_no_temporary() {
    let dir = scratch();
    let path = dir.join("out.csv");
    output::write(&path, b"old\n").unwrap();
    let err = output::write_with(&path, |w| {
        w.write_all(b"half of the new")?;
        Err(io::Error::other("the producer failed"))
    })
    .unwrap_err();
    assert!(err.to_string().contains("out.csv"), "{err}");
    assert_eq!(fs::read(&path).unwrap(), b"old\n");
    assert_eq!(names(&dir), ["out.csv"]);
    fs::remove_dir_all(&dir).unwrap();
}

#[cfg(target_os = "linux")]
#[test]
fn a_full_device_is_an_error() {
    let err = output::write(std::path::Path::new("/dev/full"), &[b'x'; 100_000]).unwrap_err();
    assert!(err.to_string().contains("/dev/full"), "{err}");
    // /dev/full is still the device, not a regular file put in its place.
    assert!(!fs::metadata("/dev/full").unwrap().is_file());
}

#[cfg(unix)]
#[test]
fn an_existing_file_keeps_its_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch();
    let path = dir.join("experience.json");
    output::write(&path, b"1").unwrap();
    fs::set_permissions(&path, fs::Permissions::from_mode(0o600)).unwrap();
    output::write(&path, b"2").unwrap();
    assert_eq!(
        fs::metadata(&path).unwrap().permissions().mode() & 0o777,
        0o600
    );
    assert_eq!(fs::read(&path).unwrap(), b"2");
    fs::remove_dir_all(&dir).unwrap();
}

#[cfg(unix)]
#[test]
fn writing_through_a_symlink_replaces_its_target_and_keeps_the_link() {
    let dir = scratch();
    fs::create_dir(dir.join("real")).unwrap();
    let target = dir.join("real/model.json");
    output::write(&target, b"old").unwrap();
    let link = dir.join("model.json");
    std::os::unix::fs::symlink("real/model.json", &link).unwrap();
    output::write(&link, b"new").unwrap();
    assert!(
        fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(fs::read(&target).unwrap(), b"new");
    // A dangling link creates the file it names.
    let dangling = dir.join("later.json");
    std::os::unix::fs::symlink("real/later.json", &dangling).unwrap();
    output::write(&dangling, b"x").unwrap();
    assert_eq!(fs::read(dir.join("real/later.json")).unwrap(), b"x");
    fs::remove_dir_all(&dir).unwrap();
}

#[cfg(target_os = "linux")]
#[test]
fn temporaries_of_dead_processes_are_removed_and_others_kept() {
    let dir = scratch();
    // No process has an id this large (Linux's pid_max is at most 2^22).
    let dead = dir.join(".runs.json.AbCdEf.tmp-4294967");
    let alive = dir.join(format!(".runs.json.GhIjKl.tmp-{}", std::process::id()));
    let other = dir.join(".notes.txt.AbCdEf.tmp-4294967");
    for path in [&dead, &alive, &other] {
        fs::write(path, b"partial").unwrap();
    }
    output::write(&dir.join("runs.json"), b"[]").unwrap();
    assert!(!dead.exists());
    assert!(alive.exists() && other.exists());
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_directory_is_refused() {
    let dir = scratch();
    let err = output::write(&dir, b"x").unwrap_err();
    assert!(dir.is_dir(), "{err}");
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_staging_directory_replaces_files_only_when_committed() {
    let root = scratch();
    let out = root.join("results");
    fs::create_dir(&out).unwrap();
    fs::write(out.join("REPORT.md"), "old report").unwrap();
    fs::write(out.join("example.json"), "old example").unwrap();
    fs::write(out.join("notes.txt"), "the user's own file").unwrap();

    // A run that fails: dropped without a commit, nothing changes.
    {
        let staging = Staging::new(&out).unwrap();
        fs::write(staging.path().join("REPORT.md"), "half").unwrap();
    }
    assert_eq!(names(&root), ["results"]);
    assert_eq!(
        fs::read_to_string(out.join("REPORT.md")).unwrap(),
        "old report"
    );

    // A run that succeeds without an example: the old example is obsolete.
    let staging = Staging::new(&out).unwrap();
    fs::write(staging.path().join("REPORT.md"), "new report").unwrap();
    fs::write(staging.path().join("runs.json"), "[]").unwrap();
    staging.commit(&["example.json", "runs.csv"]).unwrap();
    assert_eq!(names(&root), ["results"]);
    assert_eq!(names(&out), ["REPORT.md", "notes.txt", "runs.json"]);
    assert_eq!(
        fs::read_to_string(out.join("REPORT.md")).unwrap(),
        "new report"
    );

    // A destination that does not exist yet is created.
    let fresh = root.join("a/b");
    let staging = Staging::new(&fresh).unwrap();
    fs::write(staging.path().join("runs.json"), "[]").unwrap();
    staging.commit(&[]).unwrap();
    assert_eq!(names(&fresh), ["runs.json"]);
    fs::remove_dir_all(&root).unwrap();
}

/// Every file of a directory with its text, by relative path; `None` for none.
type Tree = Option<Vec<(String, String)>>;

/// Every file under `dir` with its text, by path relative to `dir`; `None` when
/// `dir` does not exist.
fn tree(dir: &Path) -> Tree {
    fn walk(dir: &Path, base: &Path, out: &mut Vec<(String, String)>) {
        for entry in fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, base, out);
            } else {
                let name = path.strip_prefix(base).unwrap().display().to_string();
                out.push((name, fs::read_to_string(&path).unwrap()));
            }
        }
    }
    if !dir.exists() {
        return None;
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    Some(out)
}

fn files(entries: &[(&str, &str)]) -> Tree {
    let mut out: Vec<(String, String)> = entries
        .iter()
        .map(|(a, b)| ((*a).to_owned(), (*b).to_owned()))
        .collect();
    out.sort();
    Some(out)
}

/// The results of an earlier run (with the user's note and a nested evaluation),
/// and the staged results of a new one, which no longer writes `example.json`.
fn old_and_new(root: &Path) -> (PathBuf, Staging) {
    let out = root.join("results");
    fs::create_dir_all(out.join("safe")).unwrap();
    for (name, text) in OLD {
        fs::write(out.join(name), text).unwrap();
    }
    let staging = Staging::new(&out).unwrap();
    for (name, text) in STAGED {
        fs::write(staging.path().join(name), text).unwrap();
    }
    (out, staging)
}

const OLD: [(&str, &str); 5] = [
    ("REPORT.md", "old report"),
    ("runs.csv", "old runs"),
    ("example.json", "old example"),
    ("notes.txt", "the user's own file"),
    ("safe/REPORT.md", "old safe report"),
];
const STAGED: [(&str, &str); 3] = [
    ("REPORT.md", "new report"),
    ("runs.csv", "new runs"),
    ("fig07.svg", "new figure"),
];
const NEW: [(&str, &str); 5] = [
    ("REPORT.md", "new report"),
    ("runs.csv", "new runs"),
    ("fig07.svg", "new figure"),
    ("notes.txt", "the user's own file"),
    ("safe/REPORT.md", "old safe report"),
];
const OBSOLETE: &[&str] = &["example.json"];

/// Commits the staged results of [`old_and_new`] with a fault at step `fail_at`
/// (the fault `kind`), checking before every step that the destination holds the
/// whole old or the whole new results; returns the steps taken and the outcome.
fn commit_checked(
    fail_at: Option<usize>,
    kind: io::ErrorKind,
    exchange_unsupported: bool,
) -> (Vec<CommitStep>, bool, Tree) {
    let root = scratch();
    let (out, staging) = old_and_new(&root);
    let mut steps = Vec::new();
    let result = staging.commit_with(OBSOLETE, |step| {
        let now = tree(&out);
        let allowed_missing = *step == CommitStep::MoveIn && exchange_unsupported;
        assert!(
            now == files(&OLD) || now == files(&NEW) || (allowed_missing && now.is_none()),
            "before {step:?} the destination holds {now:?}"
        );
        steps.push(step.clone());
        if exchange_unsupported && *step == CommitStep::Exchange {
            return Err(io::Error::from(io::ErrorKind::Unsupported));
        }
        if fail_at == Some(steps.len() - 1) {
            return Err(io::Error::new(kind, "injected fault"));
        }
        Ok(())
    });
    let after = tree(&out);
    fs::remove_dir_all(&root).unwrap();
    (steps, result.is_ok(), after)
}

#[test]
fn a_commit_leaves_the_whole_old_or_the_whole_new_results_before_every_step() {
    let (steps, committed, after) = commit_checked(None, io::ErrorKind::Other, false);
    assert!(committed);
    assert_eq!(after, files(&NEW));
    // notes.txt and safe/ carried over, example.json obsolete.
    #[cfg(any(target_os = "linux", target_vendor = "apple"))]
    assert_eq!(
        steps,
        [
            CommitStep::Carry("notes.txt".into()),
            CommitStep::Carry("safe".into()),
            CommitStep::Exchange,
            CommitStep::RemovePrevious,
        ]
    );
}

#[test]
fn a_fault_between_any_two_steps_of_a_commit_leaves_the_old_or_the_new_results() {
    let (steps, _, _) = commit_checked(None, io::ErrorKind::Other, false);
    for (k, step) in steps.iter().enumerate() {
        for kind in [io::ErrorKind::Other, io::ErrorKind::StorageFull] {
            let (_, committed, after) = commit_checked(Some(k), kind, false);
            if *step == CommitStep::RemovePrevious {
                // The results are in place; the leftover goes with the next commit.
                assert!(committed, "a fault at {step:?}");
                assert_eq!(after, files(&NEW), "a fault at {step:?}");
            } else {
                assert!(!committed, "a fault at {step:?}");
                assert_eq!(after, files(&OLD), "a fault at {step:?}");
            }
        }
    }
}

#[test]
fn without_an_exchange_a_commit_renames_aside_and_back_on_a_fault() {
    let (steps, committed, after) = commit_checked(None, io::ErrorKind::Other, true);
    assert!(committed);
    assert_eq!(after, files(&NEW));
    let tail = &steps[steps.len() - 4..];
    assert_eq!(
        tail,
        [
            CommitStep::Exchange,
            CommitStep::MoveAside,
            CommitStep::MoveIn,
            CommitStep::RemovePrevious,
        ]
    );
    for k in 0..steps.len() - 1 {
        if steps[k] == CommitStep::Exchange {
            continue;
        }
        let (_, committed, after) = commit_checked(Some(k), io::ErrorKind::Other, true);
        assert!(!committed, "a fault at {:?}", steps[k]);
        assert_eq!(after, files(&OLD), "a fault at {:?}", steps[k]);
    }
}

#[test]
fn a_previous_destination_left_aside_by_a_killed_commit_is_put_back() {
    let root = scratch();
    let out = root.join("results");
    // What a commit killed between its two renames leaves: no destination, and the
    // previous one under the hidden name of a process that has ended.
    let aside = root.join(".results.previous.tmp-999999999");
    fs::create_dir(&aside).unwrap();
    fs::write(aside.join("REPORT.md"), "old report").unwrap();
    let staging = Staging::new(&out).unwrap();
    assert_eq!(tree(&out), files(&[("REPORT.md", "old report")]));
    drop(staging);
    assert_eq!(names(&root), ["results"]);
    fs::remove_dir_all(&root).unwrap();
}

#[test]
fn a_staging_destination_that_is_a_file_is_refused_and_a_link_is_kept() {
    let root = scratch();
    let file = root.join("results");
    fs::write(&file, "not a directory").unwrap();
    let err = Staging::new(&file).unwrap_err();
    assert!(err.to_string().contains("not a directory"), "{err}");
    assert_eq!(fs::read_to_string(&file).unwrap(), "not a directory");
    assert_eq!(names(&root), ["results"]);

    #[cfg(unix)]
    {
        let real = root.join("real");
        fs::create_dir(&real).unwrap();
        fs::write(real.join("REPORT.md"), "old report").unwrap();
        let link = root.join("link");
        std::os::unix::fs::symlink("real", &link).unwrap();
        let staging = Staging::new(&link).unwrap();
        fs::write(staging.path().join("REPORT.md"), "new report").unwrap();
        staging.commit(&[]).unwrap();
        assert!(
            fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(
            fs::read_to_string(real.join("REPORT.md")).unwrap(),
            "new report"
        );
        assert_eq!(names(&root), ["link", "real", "results"]);
    }
    fs::remove_dir_all(&root).unwrap();
}

#[cfg(unix)]
#[test]
fn a_committed_directory_keeps_the_permissions_of_the_previous_one() {
    use std::os::unix::fs::PermissionsExt;
    let root = scratch();
    let out = root.join("results");
    fs::create_dir(&out).unwrap();
    fs::set_permissions(&out, fs::Permissions::from_mode(0o750)).unwrap();
    let staging = Staging::new(&out).unwrap();
    fs::write(staging.path().join("REPORT.md"), "new").unwrap();
    staging.commit(&[]).unwrap();
    let mode = fs::metadata(&out).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o750);
    fs::remove_dir_all(&root).unwrap();
}

/// Issue 47: output names of 240 bytes and more failed in every writer (the
/// temporary's name was longer than the file system allows).
#[test]
fn names_up_to_the_file_systems_limit_can_be_written() {
    let root = scratch();
    let name = format!("{}.json", "n".repeat(250));
    assert_eq!(name.len(), 255);
    let path = root.join(&name);
    output::write(&path, b"old").unwrap();
    output::write(&path, b"new").unwrap();
    assert_eq!(fs::read(&path).unwrap(), b"new");
    assert_eq!(names(&root), [name]);
    let out = root.join("d".repeat(255));
    for text in ["old", "new"] {
        let staging = Staging::new(&out).unwrap();
        fs::write(staging.path().join("REPORT.md"), text).unwrap();
        staging.commit(&[]).unwrap();
    }
    assert_eq!(fs::read_to_string(out.join("REPORT.md")).unwrap(), "new");
    assert_eq!(names(&root).len(), 2);
    fs::remove_dir_all(&root).unwrap();
}
