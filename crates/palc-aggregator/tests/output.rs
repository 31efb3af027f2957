//! The output writer: every failure leaves the previous file, permissions and
//! links are kept, temporaries of dead processes are removed.

use std::fs;
use std::io;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

use palc_aggregator::output::{self, Staging};

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
    staging
        .commit(&["REPORT.md"], &["example.json", "runs.csv"])
        .unwrap();
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
    staging.commit(&[], &[]).unwrap();
    assert_eq!(names(&fresh), ["runs.json"]);
    fs::remove_dir_all(&root).unwrap();
}
