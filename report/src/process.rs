//! Running a stage as a child process and reading what it cost from the kernel: wall time, CPU
//! time (user + system, all threads) and peak resident memory, from `wait4`'s resource usage of
//! that one child.

use std::fs::File;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

use crate::ReportError;

/// What one run of a stage cost.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Timing {
    /// Seconds from start to exit.
    pub wall_seconds: f64,
    /// CPU seconds, user and system, of all its threads.
    pub cpu_seconds: f64,
    /// Peak resident memory in MiB.
    pub peak_rss_mb: f64,
}

impl Timing {
    /// The better of two runs: the one with less wall time.
    pub fn best(a: Option<Timing>, b: Timing) -> Timing {
        match a {
            Some(a) if a.wall_seconds <= b.wall_seconds => a,
            _ => b,
        }
    }
}

/// Runs `command` with its output in `log` and returns what it cost; a non-zero exit is an error
/// quoting the end of the log.
pub fn run_timed(command: &mut Command, log: &Path) -> Result<Timing, ReportError> {
    let out = File::create(log).map_err(ReportError::io(log))?;
    let err = out.try_clone().map_err(ReportError::io(log))?;
    command
        .stdin(Stdio::null())
        .stdout(Stdio::from(out))
        .stderr(Stdio::from(err));
    let shown = format!("{command:?}");
    let start = Instant::now();
    let child = command
        .spawn()
        .map_err(ReportError::io(command.get_program()))?;
    let (status, usage) = wait_for(child.id())?;
    let wall_seconds = start.elapsed().as_secs_f64();
    // The child is reaped by `wait_for`; std's handle must not wait for it again.
    drop(child);
    if !(libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0) {
        let status = if libc::WIFEXITED(status) {
            format!("exited with status {}", libc::WEXITSTATUS(status))
        } else {
            format!("was killed by signal {}", libc::WTERMSIG(status))
        };
        return Err(ReportError::CommandFailed {
            command: shown,
            status,
            log: log.to_path_buf(),
            tail: log_tail(log),
        });
    }
    let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    Ok(Timing {
        wall_seconds,
        cpu_seconds: seconds(usage.ru_utime) + seconds(usage.ru_stime),
        // Linux gives kilobytes.
        peak_rss_mb: usage.ru_maxrss as f64 / 1024.0,
    })
}

/// Waits for child `pid`, returning its wait status and resource usage.
fn wait_for(pid: u32) -> Result<(i32, libc::rusage), ReportError> {
    let pid = pid as libc::pid_t;
    let mut status = 0;
    // SAFETY: `rusage` is plain old data, for which all zero bytes are a valid value.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    loop {
        // SAFETY: `pid` is our own child, not yet waited for; both pointers are to live locals.
        let got = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
        if got == pid {
            return Ok((status, usage));
        }
        let error = std::io::Error::last_os_error();
        if error.kind() != std::io::ErrorKind::Interrupted {
            return Err(ReportError::Io {
                path: format!("wait4 on child {pid}").into(),
                source: error,
            });
        }
    }
}

/// The last lines of a log, for an error message.
fn log_tail(log: &Path) -> String {
    let text = std::fs::read(log).unwrap_or_default();
    let text = String::from_utf8_lossy(&text);
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(8)..].join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_child_is_timed_and_its_failure_quoted() {
        let dir = std::env::temp_dir().join(format!("report-process-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let log = dir.join("log");
        let t = run_timed(Command::new("sh").args(["-c", "echo hello"]), &log).expect("runs");
        assert!(t.wall_seconds >= 0.0 && t.cpu_seconds >= 0.0 && t.peak_rss_mb > 0.0);
        let failed = run_timed(Command::new("sh").args(["-c", "echo broken; exit 3"]), &log);
        let Err(ReportError::CommandFailed { status, tail, .. }) = failed else {
            panic!("a failing child is an error: {failed:?}");
        };
        assert_eq!(
            (status.as_str(), tail.as_str()),
            ("exited with status 3", "broken")
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
