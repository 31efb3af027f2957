//! The input reader: a file past the bound is refused from its size, a stream
//! once the bound is read; every error names the file.

use std::path::{Path, PathBuf};

use palc_aggregator::input::{InputError, read, read_bounded, read_to_string};

fn scratch(name: &str) -> PathBuf {
    let path = std::env::temp_dir().join(format!("palc-input-{}-{name}", std::process::id()));
    let _ = std::fs::remove_file(&path);
    path
}

#[test]
fn a_file_past_the_bound_is_refused_naming_it_its_size_and_the_bound() {
    let path = scratch("large");
    std::fs::write(&path, [b'x'; 11]).unwrap();
    assert_eq!(read_bounded(&path, 11).unwrap().len(), 11);
    let error = read_bounded(&path, 10).unwrap_err();
    let message = error.to_string();
    assert!(
        message.contains(&path.display().to_string())
            && message.contains("11 bytes")
            && message.contains("10 bytes"),
        "{message}"
    );
    assert!(matches!(
        error,
        InputError::TooLarge {
            size: Some(11),
            bound: 10,
            ..
        }
    ));
    assert!(error.into_io().to_string().contains("10 bytes"));
    std::fs::remove_file(&path).unwrap();
}

#[cfg(target_os = "linux")]
#[test]
fn an_endless_stream_is_read_up_to_the_bound_and_refused() {
    let error = read_bounded(Path::new("/dev/zero"), 1000).unwrap_err();
    let message = error.to_string();
    assert!(
        message.contains("/dev/zero") && message.contains("1000 bytes"),
        "{message}"
    );
    assert!(matches!(error, InputError::TooLarge { size: None, .. }));
}

#[test]
fn a_directory_or_a_missing_file_is_an_error_naming_it() {
    let dir = std::env::temp_dir();
    assert!(read(&dir).unwrap_err().to_string().contains("directory"));
    let missing = scratch("missing");
    let message = read(&missing).unwrap_err().to_string();
    assert!(
        message.contains(&missing.display().to_string()),
        "{message}"
    );
    let text = scratch("latin1");
    std::fs::write(&text, [0xE9]).unwrap();
    assert!(read_to_string(&text).is_err());
    std::fs::remove_file(&text).unwrap();
}
