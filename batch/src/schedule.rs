//! Running maps side by side within a memory budget.
//!
//! Each map is given an estimate of the memory its stages take at their peak (the compile's, by
//! far the largest: see [`estimate_memory`]). A worker starts the first waiting map whose estimate
//! fits in what the running maps leave of the budget; a map larger than the whole budget runs
//! when nothing else does. The stages themselves share one pool of threads (rayon's), so `jobs`
//! bounds how many maps are in flight, not how many cores are used.

use std::sync::{Condvar, Mutex};

/// Bytes a map's build is estimated to need at its peak, from the size of its `.map` file.
///
/// Fitted to the compile's measured peak resident memory (the README's table): id's e1m1 (673 KB
/// of `.map`, 79 MB) and LibreQuake's e3m4 (3.16 MB, 272 MB) give about 80 bytes per byte of map
/// plus a base of 32 MiB. Vis and light peak lower on both.
pub fn estimate_memory(map_bytes: u64) -> u64 {
    (32 << 20) + 80 * map_bytes
}

/// The memory to budget by default: what the system says is available now (Linux's
/// `MemAvailable`), else 4 GiB.
pub fn default_memory_budget() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find_map(|l| l.strip_prefix("MemAvailable:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        })
        .map_or(4 << 30, |kib| kib << 10)
}

/// `4G`, `512M`, `1.5G`, `800K` or a number of bytes.
pub fn parse_memory(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let (number, unit) = match t.char_indices().find(|(_, c)| c.is_ascii_alphabetic()) {
        Some((i, _)) => t.split_at(i),
        None => (t, ""),
    };
    let scale: u64 = match unit.to_ascii_uppercase().trim_end_matches(['B', 'I']) {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        "T" => 1 << 40,
        _ => return Err(format!("{text:?}: the unit must be K, M, G or T")),
    };
    let value: f64 = number
        .trim()
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite() && *v > 0.0)
        .ok_or_else(|| format!("{text:?} is not a positive size such as 4G or 512M"))?;
    Ok((value * scale as f64) as u64)
}

struct State {
    waiting: Vec<usize>,
    in_use: u64,
    running: usize,
}

/// Run `work` on every item (each with its memory estimate), at most `jobs` at once and within
/// `budget`; results in the items' order.
pub fn run_within_budget<T: Sync, R: Send>(
    items: &[(u64, T)],
    jobs: usize,
    budget: u64,
    work: impl Fn(&T) -> R + Sync,
) -> Vec<R> {
    let state = Mutex::new(State {
        waiting: (0..items.len()).collect(),
        in_use: 0,
        running: 0,
    });
    let changed = Condvar::new();
    let results: Mutex<Vec<Option<R>>> = Mutex::new((0..items.len()).map(|_| None).collect());
    let next = || -> Option<usize> {
        let mut s = state.lock().unwrap_or_else(|e| e.into_inner());
        loop {
            if s.waiting.is_empty() {
                return None;
            }
            let fits = s
                .waiting
                .iter()
                .position(|&i| s.running == 0 || s.in_use + items[i].0 <= budget);
            if let Some(at) = fits {
                let i = s.waiting.remove(at);
                s.in_use += items[i].0;
                s.running += 1;
                return Some(i);
            }
            s = changed.wait(s).unwrap_or_else(|e| e.into_inner());
        }
    };
    std::thread::scope(|scope| {
        for _ in 0..jobs.clamp(1, items.len().max(1)) {
            scope.spawn(|| {
                while let Some(i) = next() {
                    let result = work(&items[i].1);
                    results.lock().unwrap_or_else(|e| e.into_inner())[i] = Some(result);
                    let mut s = state.lock().unwrap_or_else(|e| e.into_inner());
                    s.in_use -= items[i].0;
                    s.running -= 1;
                    changed.notify_all();
                }
            });
        }
    });
    results
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .flatten()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU64, Ordering};

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_memory("4G"), Ok(4 << 30));
        assert_eq!(parse_memory("512MiB"), Ok(512 << 20));
        assert_eq!(parse_memory("1.5g"), Ok(3 << 29));
        assert_eq!(parse_memory("1000"), Ok(1000));
        assert!(parse_memory("-1G").is_err() && parse_memory("4Q").is_err());
    }

    #[test]
    fn the_budget_is_never_exceeded_and_every_item_runs() {
        let in_use = AtomicU64::new(0);
        let peak = AtomicU64::new(0);
        // The 250 item is larger than the budget: it must still run, alone.
        let items: Vec<(u64, u64)> = [40, 60, 30, 250, 50, 10, 70]
            .into_iter()
            .map(|m| (m, m))
            .collect();
        let results = run_within_budget(&items, 4, 100, |&m| {
            let now = in_use.fetch_add(m, Ordering::SeqCst) + m;
            peak.fetch_max(now, Ordering::SeqCst);
            assert!(now <= 100 || now == m, "{now} in use with a {m} item");
            std::thread::sleep(std::time::Duration::from_millis(20));
            in_use.fetch_sub(m, Ordering::SeqCst);
            m * 2
        });
        assert_eq!(results, [80, 120, 60, 500, 100, 20, 140]);
        assert!(peak.load(Ordering::SeqCst) >= 250);
    }
}
