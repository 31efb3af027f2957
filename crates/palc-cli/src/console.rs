//! Lines for the user on stdout and stderr that never panic.
//!
//! `println!` panics when stdout is closed (`palc learn | head -1`). Here a closed
//! stream (`EPIPE`) is remembered and later lines to it are dropped, so the command
//! finishes its work and saves its outputs; it then ends quietly with success, as
//! `git` and `ripgrep` do. Any other failure to write (a full disk behind a
//! redirection) is kept and reported when the command ends.

use std::fmt;
use std::io::{self, Write};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);
static STDERR_CLOSED: AtomicBool = AtomicBool::new(false);
static FAILURE: Mutex<Option<io::Error>> = Mutex::new(None);

/// Prints a line on stdout (a message, not the command's data).
macro_rules! say {
    ($($arg:tt)*) => { $crate::console::line(false, format_args!($($arg)*)) };
}

/// Prints a line on stderr.
macro_rules! warning {
    ($($arg:tt)*) => { $crate::console::line(true, format_args!($($arg)*)) };
}

pub(crate) use {say, warning};

/// Writes one line to stdout (or stderr); see the module's documentation.
pub fn line(to_stderr: bool, args: fmt::Arguments<'_>) {
    let closed = if to_stderr {
        &STDERR_CLOSED
    } else {
        &STDOUT_CLOSED
    };
    if closed.load(Ordering::Relaxed) {
        return;
    }
    let result = if to_stderr {
        writeln!(io::stderr().lock(), "{args}")
    } else {
        let mut stdout = io::stdout().lock();
        writeln!(stdout, "{args}").and_then(|()| stdout.flush())
    };
    if let Err(error) = result {
        closed.store(true, Ordering::Relaxed);
        remember(error);
    }
}

/// Writes the command's data (a plan, classified points) to stdout, checked.
pub fn data(bytes: &[u8]) -> io::Result<()> {
    if STDOUT_CLOSED.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut stdout = io::stdout().lock();
    let result = stdout.write_all(bytes).and_then(|()| stdout.flush());
    if let Err(error) = &result {
        if error.kind() == io::ErrorKind::BrokenPipe {
            STDOUT_CLOSED.store(true, Ordering::Relaxed);
            return Ok(());
        }
    }
    result
}

fn remember(error: io::Error) {
    if error.kind() == io::ErrorKind::BrokenPipe {
        return;
    }
    if let Ok(mut failure) = FAILURE.lock() {
        failure.get_or_insert(error);
    }
}

/// The first failure to write a line that was not a closed pipe, if any.
pub fn failure() -> Option<io::Error> {
    FAILURE.lock().ok().and_then(|mut f| f.take())
}

/// Whether `error` comes from a closed pipe (the reader has gone away).
pub fn is_broken_pipe(error: &anyhow::Error) -> bool {
    error.chain().any(|cause| {
        cause
            .downcast_ref::<io::Error>()
            .is_some_and(|e| e.kind() == io::ErrorKind::BrokenPipe)
    })
}

/// Reports the error that ends the command on stderr, if stderr is still open.
pub fn report(error: &anyhow::Error) {
    if !STDERR_CLOSED.load(Ordering::Relaxed) {
        let _ = writeln!(io::stderr().lock(), "{}", rendered(error));
    }
}

/// `error` for the user: its message, then each cause the message above it
/// does not already quote (the library errors name their cause in their own
/// message, so a plain chain said the operating system's error twice), then
/// the backtrace when one was captured (`RUST_BACKTRACE=1`). Numbers a parser
/// wrote out in full are shortened ([`shortest_numbers`]).
fn rendered(error: &anyhow::Error) -> String {
    let mut text = format!("Error: {error}");
    let mut above = error.to_string();
    for cause in error.chain().skip(1) {
        let message = cause.to_string();
        if !above.contains(&message) {
            text.push_str(&format!("\n  caused by: {message}"));
        }
        above = message;
    }
    let mut text = shortest_numbers(&text);
    let backtrace = error.backtrace();
    if backtrace.status() == std::backtrace::BacktraceStatus::Captured {
        text.push_str(&format!("\n\nStack backtrace:\n{backtrace}"));
    }
    text
}

/// Longest number written out as it is: more digits than any `f64` needs
/// (17 significant, a sign, a point and a few zeros).
const LONGEST_PLAIN_NUMBER: usize = 24;

/// `text` with every decimal number longer than [`LONGEST_PLAIN_NUMBER`]
/// characters written in its shortest round-trip form (`1e300` for the 301
/// digits a parser's message may print for it).
fn shortest_numbers(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < bytes.len() {
        let starts_number = bytes[i].is_ascii_digit()
            || (bytes[i] == b'-' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit));
        let after_word = i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
        if starts_number && !after_word {
            let mut end = i + 1;
            while end < bytes.len() && (bytes[end].is_ascii_digit() || bytes[end] == b'.') {
                end += 1;
            }
            let token = &text[i..end];
            match token.parse::<f64>() {
                Ok(value) if token.len() > LONGEST_PLAIN_NUMBER => {
                    out.push_str(&format!("{value:?}"))
                }
                _ => out.push_str(token),
            }
            i = end;
        } else {
            let next = text[i..].chars().next().map_or(1, char::len_utf8);
            out.push_str(&text[i..i + next]);
            i += next;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_a_parser_writes_out_in_full_are_shortened() {
        let huge = format!("{}", 1e300);
        let tiny = format!("{}", -1e-300);
        let text = format!(
            "floating point `{huge}`, expected u64; speed {tiny} m/s; seed 18446744073709551615, v2 3.5"
        );
        assert_eq!(
            shortest_numbers(&text),
            "floating point `1e300`, expected u64; speed -1e-300 m/s; seed 18446744073709551615, v2 3.5"
        );
        assert_eq!(shortest_numbers("naïve 0.1 — x"), "naïve 0.1 — x");
    }

    #[test]
    fn a_cause_the_message_already_quotes_is_not_repeated() {
        let io = io::Error::new(io::ErrorKind::NotFound, "No such file or directory");
        let error = anyhow::Error::new(io)
            .context("experience file /x.json: No such file or directory")
            .context("cannot load /x.json");
        let text = rendered(&error);
        let first_lines = text.lines().take(2).collect::<Vec<_>>();
        assert_eq!(
            first_lines,
            [
                "Error: cannot load /x.json",
                "  caused by: experience file /x.json: No such file or directory",
            ]
        );
        assert_eq!(
            text.matches("No such file or directory").count(),
            1,
            "{text}"
        );
    }

    #[test]
    fn a_cause_the_message_does_not_quote_is_shown() {
        let error = anyhow::anyhow!("the scene is too short").context("cannot run the cell");
        assert!(
            rendered(&error)
                .starts_with("Error: cannot run the cell\n  caused by: the scene is too short")
        );
    }
}
