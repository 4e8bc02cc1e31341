//! Whether the tool was started with its standard output closed (`tool >&-`).
//!
//! Rust's runtime reopens a closed stdout on /dev/null before `main`, so a write to it
//! succeeds and the output vanishes; from `main` on, a closed stdout and `>/dev/null` look the
//! same. Only code that runs before the runtime can tell them apart: a startup constructor
//! that looks at descriptor 1 and leaves the answer for [`stdout_closed`].

use std::sync::atomic::{AtomicBool, Ordering};

static CLOSED: AtomicBool = AtomicBool::new(false);

// The unsafe parts are placing the probe among the startup constructors (the loader calls
// them before `main`) and asking the kernel about a descriptor, which touches no memory.
#[cfg(target_os = "linux")]
#[allow(unsafe_code)]
mod probe {
    #[used]
    #[link_section = ".init_array"]
    pub(super) static PROBE: extern "C" fn() = probe;

    extern "C" fn probe() {
        // SAFETY: F_GETFD reads the descriptor's flags; -1 (EBADF) means descriptor 1 is not open.
        let closed = unsafe { libc::fcntl(libc::STDOUT_FILENO, libc::F_GETFD) } == -1;
        super::CLOSED.store(closed, std::sync::atomic::Ordering::Relaxed);
    }
}

/// Whether stdout was closed when the process started (always `false` where this cannot be
/// known, i.e. outside Linux). Anything written to it would be lost.
pub fn stdout_closed() -> bool {
    // The reference keeps the constructor's object in the link.
    #[cfg(target_os = "linux")]
    std::hint::black_box(probe::PROBE);
    CLOSED.load(Ordering::Relaxed)
}

/// Errors when stdout was closed at start: a result written there would be dropped silently.
pub fn require_stdout() -> Result<(), crate::IoError> {
    if stdout_closed() {
        Err(crate::IoError::StdoutClosed)
    } else {
        Ok(())
    }
}
