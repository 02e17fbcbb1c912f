//! Stopping on SIGINT (Ctrl+C) and SIGTERM (a `kill`, a session ending). [`start`], first thing in the program,
//! blocks both in every thread and waits for them in one of its own, where anything may run: a command stops with a
//! message, its temporary output files removed (export/files.rs keeps the list) and the shell's exit code, 130 or
//! 143; the viewer, which asks to [`defer`], is told instead and ends between frames as Escape does (its requested
//! screenshot written, its camera path closed, the device released).

use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};

/// The signal received while deferred, 0 while none.
static RECEIVED: AtomicI32 = AtomicI32::new(0);
/// Whether the program stops itself when told ([`requested`]).
static DEFERRED: AtomicBool = AtomicBool::new(false);

/// Routes SIGINT and SIGTERM to the stopping thread. Call before any other thread starts: threads inherit the mask.
#[cfg(unix)]
pub fn start() {
    // SAFETY: plain signal-set calls on a local set; no other thread exists yet, so the mask reaches every thread.
    let set = unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        libc::sigaddset(&mut set, libc::SIGINT);
        libc::sigaddset(&mut set, libc::SIGTERM);
        libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut());
        set
    };
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || loop {
            let mut signal = 0;
            // SAFETY: `set` is a valid, initialised signal set.
            if unsafe { libc::sigwait(&set, &mut signal) } != 0 {
                continue;
            }
            if DEFERRED.load(Ordering::SeqCst) {
                RECEIVED.store(signal, Ordering::SeqCst);
                continue;
            }
            let removed = crate::export::files::remove_partial_files();
            eprintln!(
                "riverplanet: stopped by {}; {removed} unfinished output file(s) removed, finished ones kept",
                name(signal)
            );
            std::process::exit(128 + signal);
        })
        .expect("a thread to wait for signals");
}

#[cfg(not(unix))]
pub fn start() {}

/// The caller stops itself when [`requested`] says so, instead of the process ending at the signal.
pub fn defer() {
    DEFERRED.store(true, Ordering::SeqCst);
}

/// The name of the stopping signal received while deferred, if any.
pub fn requested() -> Option<&'static str> {
    match RECEIVED.load(Ordering::SeqCst) {
        0 => None,
        signal => Some(name(signal)),
    }
}

#[cfg(unix)]
fn name(signal: i32) -> &'static str {
    if signal == libc::SIGTERM {
        "SIGTERM"
    } else {
        "SIGINT"
    }
}

#[cfg(not(unix))]
fn name(_: i32) -> &'static str {
    "SIGINT"
}
