//! Standard output that a reader who stops reading does not turn into a panic:
//! `println!` panics on a closed pipe (`aviary bench w | head -1`). Here a closed pipe
//! silences the rest of the output and the command ends with its own status; any other
//! failure to write is said once on standard error.

use std::io::{self, Write};
use std::sync::atomic::{AtomicBool, Ordering};

static FAILED: AtomicBool = AtomicBool::new(false);

pub fn write(args: std::fmt::Arguments<'_>) {
    put(|stdout| stdout.write_fmt(args));
}

/// Writes and flushes, unless standard output has failed before.
fn put(what: impl FnOnce(&mut io::StdoutLock<'static>) -> io::Result<()>) {
    if FAILED.load(Ordering::Relaxed) {
        return;
    }
    let mut stdout = io::stdout().lock();
    if let Err(e) = what(&mut stdout).and_then(|()| stdout.flush()) {
        FAILED.store(true, Ordering::Relaxed);
        if e.kind() != io::ErrorKind::BrokenPipe {
            eprintln!("aviary: cannot write to standard output: {e}");
        }
    }
}

/// Whether standard output has failed (the reader went away): a command that only
/// prints can stop.
pub fn closed() -> bool {
    FAILED.load(Ordering::Relaxed)
}

/// `print!` without the panic.
macro_rules! out {
    ($($arg:tt)*) => { $crate::out::write(format_args!($($arg)*)) };
}

/// `println!` without the panic.
macro_rules! outln {
    () => { $crate::out::write(format_args!("\n")) };
    ($($arg:tt)*) => { $crate::out::write(format_args!("{}\n", format_args!($($arg)*))) };
}

/// Standard output as an `io::Write`, for reports written by a library (`aviary_bench`):
/// each `write!` is one `out!`, so a reader that stops reading silences the rest, and the
/// writes never fail.
pub struct Stdout;

impl Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        put(|stdout| stdout.write_all(buf));
        Ok(buf.len())
    }

    fn write_fmt(&mut self, args: std::fmt::Arguments<'_>) -> io::Result<()> {
        write(args);
        Ok(())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}
