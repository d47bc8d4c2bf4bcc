//! Standard output that fails like any other write: `println!` panics (exit 101) when stdout
//! is a full disk or a closed file descriptor; [`outln!`] returns the error instead, so the
//! command ends with a message on stderr and exit 1 (`lightgrid list > /dev/full`).
//! A closed pipe (`lightgrid list | head`) still ends the process quietly by SIGPIPE
//! (`main::default_sigpipe`).

/// `println!` that returns `Err` from the enclosing function when stdout cannot be written.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*).map_err($crate::out::stdout_failed)?
    }};
}

/// The error of a failed write to stdout, naming what was being written to.
pub(crate) fn stdout_failed(e: std::io::Error) -> anyhow::Error {
    anyhow::anyhow!("cannot write to standard output: {e}")
}

/// Flush stdout before exiting: `std::process::exit` and the end of `main` do not report a
/// flush that fails, so output buffered there would be lost without a message.
pub(crate) fn flush() -> anyhow::Result<()> {
    use std::io::Write as _;
    std::io::stdout().lock().flush().map_err(stdout_failed)
}
