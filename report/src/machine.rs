//! The machine a report ran on: what its header says.

use std::path::Path;
use std::process::Command;

/// CPU, cores, the vector ISA Embree traces with, and how busy the machine was.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Machine {
    /// The CPU's model name from `/proc/cpuinfo` (`unknown` when it gives none).
    pub cpu: String,
    /// Threads the machine can run at once.
    pub cores: usize,
    /// The widest kernel set Embree both supports on this CPU and was built with.
    pub embree_isa: String,
    /// Load averages (1, 5, 15 minutes) when the report started and ended.
    pub load_start: String,
    /// Load averages when the report ended, in the same form.
    pub load_end: String,
    /// UTC date, YYYY-MM-DD.
    pub date: String,
}

impl Machine {
    /// Reads the CPU and load now; the ISA is asked of Embree by lighting `bsp` once.
    pub fn probe(slipgate: &Path, bsp: Option<&Path>, scratch: &Path) -> Machine {
        let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let cpu = cpuinfo
            .lines()
            .find_map(|l| l.strip_prefix("model name")?.split_once(':'))
            .map_or_else(|| "unknown".into(), |(_, v)| v.trim().to_string());
        Machine {
            cpu,
            cores: std::thread::available_parallelism().map_or(1, usize::from),
            embree_isa: bsp
                .and_then(|b| embree_isa(slipgate, b, scratch))
                .unwrap_or_else(|| "unknown".into()),
            load_start: load_average(),
            load_end: String::new(),
            date: utc_date(),
        }
    }
}

pub fn load_average() -> String {
    let text = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    text.split_whitespace()
        .take(3)
        .collect::<Vec<_>>()
        .join(" ")
}

/// Lights one face of `bsp` with Embree's verbose output on and reads which kernels it has.
fn embree_isa(slipgate: &Path, bsp: &Path, scratch: &Path) -> Option<String> {
    let out = Command::new(slipgate)
        .arg("light")
        .arg(bsp)
        .arg("-o")
        .arg(scratch)
        .args(["--face-stride", "1000000000"])
        .env(light::EMBREE_CONFIG_ENV, "verbose=1")
        .output()
        .ok()?;
    let _ = std::fs::remove_file(scratch);
    widest_isa(&String::from_utf8_lossy(&out.stdout))
}

/// From Embree's verbose banner: the widest target in both its "(supported)" and its
/// "(compile time enabled)" lists.
fn widest_isa(banner: &str) -> Option<String> {
    let list = |tag: &str| -> Vec<String> {
        banner
            .lines()
            .filter(|l| l.contains(tag))
            .flat_map(|l| {
                let l = l.split_once(':').map_or(l, |(_, rest)| rest);
                l.replace(tag, "")
                    .split_whitespace()
                    .map(str::to_string)
                    .collect::<Vec<_>>()
            })
            .collect()
    };
    let supported = list("(supported)");
    let built = list("(compile time enabled)");
    ["AVX512", "AVX2", "AVX", "SSE4.2", "SSE2"]
        .into_iter()
        .find(|isa| supported.iter().any(|s| s == isa) && built.iter().any(|s| s == isa))
        .map(str::to_string)
}

/// Today's UTC date from the system clock (days since 1970 to a civil date).
fn utc_date() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (y, m, d) = civil_from_days((secs / 86_400) as i64);
    format!("{y:04}-{m:02}-{d:02}")
}

/// Howard Hinnant's days-to-civil algorithm (proleptic Gregorian calendar).
fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embree_banner_gives_the_widest_kernels_built_and_supported() {
        let banner = "  Config\n    Threads : 2\n    Targets : SSE SSE2 SSE3 SSSE3 SSE4.1 SSE4.2 AVX AVXI AVX2  (supported)\n              SSE2 SSE4.2 AVX AVX2 AVX512  (compile time enabled)\n";
        assert_eq!(widest_isa(banner).as_deref(), Some("AVX2"));
        assert_eq!(widest_isa("nothing"), None);
    }

    #[test]
    fn days_become_dates() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(20_416), (2025, 11, 24));
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
    }
}
