//! Reading input files with a bound on their size: the one reader of the experience
//! store, the `palc` binary and the evaluation, as [`crate::output`] is their one
//! writer.
//!
//! An input file (a config, a problem, an experience, samples, a user file) is read
//! whole into memory before it is parsed, so its size is bounded before any work:
//! [`MAX_INPUT_BYTES`] (64 MiB, hundreds of times the largest file the workspace
//! ships). A regular file above the bound is refused from its size before a byte is
//! read; a pipe or a device (`/dev/zero`) is read up to the bound and refused when
//! it holds more. The error names the file, its size and the bound.

use std::fs::File;
use std::io::{self, Read};
use std::path::{Path, PathBuf};

/// The most bytes read from one input file (64 MiB).
pub const MAX_INPUT_BYTES: u64 = 64 * 1024 * 1024;

/// An input file could not be read, or is larger than [`MAX_INPUT_BYTES`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum InputError {
    /// The file could not be opened or read (or is not UTF-8 text where text is
    /// expected).
    #[error("cannot read {}: {error}", path.display())]
    Io {
        /// The file, as given.
        path: PathBuf,
        /// The cause; in the message, so not repeated as a `source`.
        error: io::Error,
    },
    /// The file holds more bytes than an input may.
    #[error(
        "cannot read {}: it holds {}more than the bound of {bound} bytes on an input file",
        path.display(),
        size.map_or_else(String::new, |s| format!("{s} bytes, "))
    )]
    TooLarge {
        /// The file, as given.
        path: PathBuf,
        /// Its size, when the file system tells it (a regular file); `None` for a
        /// stream that went past the bound.
        size: Option<u64>,
        /// [`MAX_INPUT_BYTES`].
        bound: u64,
    },
}

impl InputError {
    /// The cause without the path, for an error type that names the path itself.
    pub fn into_io(self) -> io::Error {
        match self {
            InputError::Io { error, .. } => error,
            InputError::TooLarge { size, bound, .. } => io::Error::new(
                io::ErrorKind::InvalidData,
                match size {
                    Some(size) => format!(
                        "it holds {size} bytes, more than the bound of {bound} bytes on an input file"
                    ),
                    None => {
                        format!("it holds more than the bound of {bound} bytes on an input file")
                    }
                },
            ),
        }
    }
}

/// Reads the bytes of the input file at `path`, at most [`MAX_INPUT_BYTES`].
///
/// # Errors
/// [`InputError`] naming `path`: it cannot be read, or it is too large.
pub fn read(path: &Path) -> Result<Vec<u8>, InputError> {
    read_bounded(path, MAX_INPUT_BYTES)
}

/// Reads the input file at `path` as UTF-8 text, at most [`MAX_INPUT_BYTES`].
///
/// # Errors
/// [`InputError`] naming `path`: it cannot be read, it is too large, or it is not
/// UTF-8.
pub fn read_to_string(path: &Path) -> Result<String, InputError> {
    let bytes = read(path)?;
    String::from_utf8(bytes).map_err(|e| InputError::Io {
        path: path.to_owned(),
        error: io::Error::new(io::ErrorKind::InvalidData, e.utf8_error()),
    })
}

/// [`read`] with another bound (for tests of the bound itself, and for inputs
/// that are outputs of palc, such as an evaluation shard's runs).
///
/// # Errors
/// [`InputError`] naming `path`.
pub fn read_bounded(path: &Path, bound: u64) -> Result<Vec<u8>, InputError> {
    let io_error = |error| InputError::Io {
        path: path.to_owned(),
        error,
    };
    let too_large = |size| InputError::TooLarge {
        path: path.to_owned(),
        size,
        bound,
    };
    let file = File::open(path).map_err(io_error)?;
    let metadata = file.metadata().map_err(io_error)?;
    if metadata.is_dir() {
        return Err(io_error(io::Error::new(
            io::ErrorKind::IsADirectory,
            "the path is a directory, not a file",
        )));
    }
    if metadata.is_file() && metadata.len() > bound {
        return Err(too_large(Some(metadata.len())));
    }
    let mut bytes = Vec::new();
    // One byte past the bound tells a stream that is too long from one that fits.
    file.take(bound.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io_error)?;
    if bytes.len() as u64 > bound {
        return Err(too_large(None));
    }
    Ok(bytes)
}
