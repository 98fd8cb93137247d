//! Standard output that a reader who stops reading does not turn into a panic:
//! `println!` panics on a closed pipe (`aviary bench w | head -1`). Here a closed pipe
//! silences the rest of the output and the command ends with its own status; any other
//! failure to write is said once on standard error.

use std::io::{self, Write};
use std::sync::atomic::{AtomicBool, Ordering};

static FAILED: AtomicBool = AtomicBool::new(false);

pub fn write(args: std::fmt::Arguments<'_>) {
    if FAILED.load(Ordering::Relaxed) {
        return;
    }
    let mut stdout = io::stdout().lock();
    if let Err(e) = stdout.write_fmt(args).and_then(|()| stdout.flush()) {
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
