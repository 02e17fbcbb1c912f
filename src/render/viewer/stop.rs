//! Stopping the viewer from outside: SIGTERM (a `kill`, a session ending) and SIGINT (Ctrl+C in its terminal) end
//! it as Escape does, between frames: the requested screenshot is written, the camera path closed and the device
//! released, instead of the process dying mid-frame.

use std::sync::atomic::{AtomicI32, Ordering};

/// The signal received, 0 while none.
static RECEIVED: AtomicI32 = AtomicI32::new(0);

extern "C" fn record(signal: libc::c_int) {
    // Only an atomic store: all a signal handler may safely do here.
    RECEIVED.store(signal, Ordering::SeqCst);
}

/// Routes SIGTERM and SIGINT to [`requested`] instead of ending the process.
pub(super) fn install() {
    let handler = record as extern "C" fn(libc::c_int) as libc::sighandler_t;
    // SAFETY: `record` is async-signal-safe (one atomic store) and lives as long as the process.
    unsafe {
        libc::signal(libc::SIGTERM, handler);
        libc::signal(libc::SIGINT, handler);
    }
}

/// The name of the stopping signal received, if any.
pub(super) fn requested() -> Option<&'static str> {
    match RECEIVED.load(Ordering::SeqCst) {
        0 => None,
        libc::SIGTERM => Some("SIGTERM"),
        _ => Some("SIGINT"),
    }
}
