//! Progress of a stage's long phases, reported to whoever shows it: every stage takes a
//! [`Progress`], and the command lines draw it as a bar.

use std::sync::Arc;

/// One progress report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProgressEvent {
    /// A phase starts with `total` units of work.
    Start {
        /// What the phase does, for the bar's label (`"brushes"`).
        phase: &'static str,
        /// Units of work the phase will report done.
        total: u64,
    },
    /// `n` more units of the current phase are done.
    Advance(u64),
    /// The current phase is over.
    Finish,
}

/// Where progress reports go; nowhere by default.
#[derive(Clone, Default)]
pub struct Progress(Option<Arc<dyn Fn(ProgressEvent) + Send + Sync>>);

impl std::fmt::Debug for Progress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.is_some() {
            "Progress(reported)"
        } else {
            "Progress(none)"
        })
    }
}

impl Progress {
    /// Reports go to `sink`, from any thread.
    pub fn new(sink: impl Fn(ProgressEvent) + Send + Sync + 'static) -> Progress {
        Progress(Some(Arc::new(sink)))
    }

    fn send(&self, event: ProgressEvent) {
        if let Some(sink) = &self.0 {
            sink(event);
        }
    }

    /// A phase starts with `total` units of work.
    pub fn start(&self, phase: &'static str, total: usize) {
        self.send(ProgressEvent::Start {
            phase,
            total: total as u64,
        });
    }

    /// `n` more units of the current phase are done.
    pub fn advance(&self, n: usize) {
        if n > 0 {
            self.send(ProgressEvent::Advance(n as u64));
        }
    }

    /// The current phase is over.
    pub fn finish(&self) {
        self.send(ProgressEvent::Finish);
    }
}

/// Progress drawn on stderr, one bar per phase, when stderr is a terminal (nowhere otherwise).
#[cfg(feature = "cli")]
pub fn terminal() -> Progress {
    use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
    use std::io::IsTerminal;
    use std::sync::Mutex;
    if !std::io::stderr().is_terminal() {
        return Progress::default();
    }
    let current: Mutex<Option<ProgressBar>> = Mutex::new(None);
    Progress::new(move |event| {
        let Ok(mut current) = current.lock() else {
            return;
        };
        match event {
            ProgressEvent::Start { phase, total } => {
                let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
                if let Ok(style) =
                    ProgressStyle::with_template("{msg:>8} {bar:40} {pos}/{len} {elapsed}")
                {
                    bar.set_style(style);
                }
                bar.set_message(phase);
                *current = Some(bar);
            }
            ProgressEvent::Advance(n) => {
                if let Some(bar) = current.as_ref() {
                    bar.inc(n);
                }
            }
            ProgressEvent::Finish => {
                if let Some(bar) = current.take() {
                    bar.finish_and_clear();
                }
            }
        }
    })
}
