//! SIGINT / SIGTERM ask the running command to stop cleanly: a sweep keeps every finished row
//! and writes the aggregate of what finished, a run deletes its partial recording. The
//! simulation checks the request before every physics step, so this takes milliseconds.
//! Repeated signals change nothing (`timeout` and process-group signals deliver the same one
//! twice); SIGKILL remains for a process that must die at once.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// The flag the library polls, and which signal set it.
pub(crate) struct Interrupt {
    pub(crate) flag: Arc<AtomicBool>,
    signal: Arc<AtomicUsize>,
}

impl Interrupt {
    /// Installs the handlers. If they cannot be installed, the flag never rises and the signals
    /// keep their default effect.
    pub(crate) fn install() -> Self {
        let flag = Arc::new(AtomicBool::new(false));
        let signal = Arc::new(AtomicUsize::new(0));
        for number in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            let _ = signal_hook::flag::register_usize(number, signal.clone(), number as usize);
            let _ = signal_hook::flag::register(number, flag.clone());
        }
        Self { flag, signal }
    }

    /// Whether a signal arrived.
    pub(crate) fn raised(&self) -> bool {
        self.flag.load(Ordering::Relaxed)
    }

    /// The conventional exit code of the signal that arrived (128 + its number).
    pub(crate) fn exit_code(&self) -> u8 {
        match self.signal.load(Ordering::Relaxed) {
            0 => 130,
            n => u8::try_from(128 + n).unwrap_or(130),
        }
    }

    /// The signal's name, for messages.
    pub(crate) fn name(&self) -> &'static str {
        if self.signal.load(Ordering::Relaxed) == signal_hook::consts::SIGTERM as usize {
            "SIGTERM"
        } else {
            "SIGINT"
        }
    }
}
