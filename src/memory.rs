//! The memory a run may use and what it uses now: the budget (`--memory-limit`, else the
//! lowest of the cgroup's limit, the address-space limit and the machine's memory), sizes as
//! people write them (`6G`, `512MiB`), and the process's resident memory. A route whose
//! predicted peak passes the budget is refused before its work (exit 3, SPEC.md), never
//! started to be killed.
//!
//! ```
//! use toposmooth::memory::{parse_size, size_text};
//! assert_eq!(parse_size("6G").unwrap(), 6 << 30);
//! assert_eq!(parse_size("1.5 GiB").unwrap(), 3 << 29);
//! assert_eq!(parse_size("800M").unwrap(), 800 << 20);
//! assert_eq!(size_text(3 << 29), "1.50 GiB");
//! ```

use crate::error::{Error, Result};

/// A size in bytes from `6G`, `6GiB`, `6 GB` (binary units: K, M, G, T, each ×1024), or a
/// plain number of bytes.
///
/// # Errors
/// A setting error (`memory_limit`) for anything else, or a size of 0.
pub fn parse_size(text: &str) -> Result<u64> {
    let t = text.trim();
    let split = t.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(t.len());
    let (number, unit) = (t[..split].trim(), t[split..].trim().to_ascii_lowercase());
    let scale: u64 = match unit.trim_end_matches("ib").trim_end_matches('b') {
        "" => 1,
        "k" => 1 << 10,
        "m" => 1 << 20,
        "g" => 1 << 30,
        "t" => 1 << 40,
        _ => 0,
    };
    let bad =
        || Error::setting("memory_limit", format!("`{text}` is not a size such as 6G, 512M or 2.5GiB (binary units)"));
    let value: f64 = number.parse().map_err(|_| bad())?;
    let bytes = value * scale as f64;
    if scale == 0 || !(bytes.is_finite() && bytes >= 1.0) || bytes > u64::MAX as f64 {
        return Err(bad());
    }
    Ok(bytes as u64)
}

/// `1.50 GiB`, `312 MiB`, `4.0 KiB`.
pub fn size_text(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= (1u64 << 30) as f64 {
        format!("{:.2} GiB", b / (1u64 << 30) as f64)
    } else if b >= (1u64 << 20) as f64 {
        format!("{:.0} MiB", b / (1u64 << 20) as f64)
    } else {
        format!("{:.1} KiB", b / 1024.0)
    }
}

/// The memory a run may use, and where the figure comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Budget {
    /// Bytes.
    pub bytes: u64,
    /// `--memory-limit`, the cgroup's limit, the address-space limit or the machine's memory.
    pub source: String,
    /// Whether the budget bounds the address space (`ulimit -v`), which counts every mapping
    /// (thread stacks, allocator arenas), rather than the resident memory.
    pub address_space: bool,
}

impl Budget {
    /// The budget given (`Some`: `--memory-limit`), else the machine's ([`machine_budget`]).
    pub fn of(given: Option<u64>) -> Budget {
        match given {
            Some(bytes) => Budget { bytes, source: "the memory limit given".into(), address_space: false },
            None => machine_budget(),
        }
    }

    /// What the dense kernels may add to what this budget bounds: under `ulimit -v`, the
    /// packing buffers the matrix-multiply kernels reserve once per thread (twice the last-level
    /// cache, mostly never touched: nothing of the resident memory); else nothing.
    pub fn kernel_reserve(&self) -> u64 {
        if !self.address_space {
            return 0;
        }
        let threads = match faer::get_global_parallelism() {
            faer::Par::Rayon(n) => n.get() as u64,
            faer::Par::Seq => 0,
        };
        2 * last_level_cache() * (threads + 2)
    }

    /// What the process uses now of what this budget bounds: its address space under
    /// `ulimit -v`, else its resident memory.
    pub fn in_use(&self) -> u64 {
        if self.address_space {
            address_space()
        } else {
            resident()
        }
    }
}

/// The lowest of the cgroup's memory limit (v2 `memory.max`, v1 `memory.limit_in_bytes`), the
/// address-space limit (`RLIMIT_AS`) and the machine's memory (`MemTotal`); 16 GiB where none
/// is known (not Linux).
pub fn machine_budget() -> Budget {
    let mut best: Option<(u64, &str)> = None;
    let mut consider = |bytes: Option<u64>, source: &'static str| {
        if let Some(b) = bytes.filter(|&b| b > 0) {
            if best.is_none_or(|(x, _)| b < x) {
                best = Some((b, source));
            }
        }
    };
    consider(cgroup_limit(), "the cgroup's memory limit");
    consider(address_space_limit(), "the address-space limit (ulimit -v)");
    consider(total_memory(), "the machine's memory");
    let (bytes, source) = best.unwrap_or((16 << 30, "a default (the machine's memory is unknown)"));
    let address_space = source.starts_with("the address-space");
    Budget { bytes, source: source.into(), address_space }
}

fn read_number(path: &str) -> Option<u64> {
    std::fs::read_to_string(path).ok()?.trim().parse().ok()
}

fn cgroup_limit() -> Option<u64> {
    // a limit as large as the address space means none
    let real = |b: u64| (b < (1u64 << 60)).then_some(b);
    read_number("/sys/fs/cgroup/memory.max")
        .and_then(real)
        .or_else(|| read_number("/sys/fs/cgroup/memory/memory.limit_in_bytes").and_then(real))
}

fn address_space_limit() -> Option<u64> {
    #[cfg(unix)]
    {
        let mut r = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
        // SAFETY: getrlimit writes the struct it is given
        let ok = unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut r) } == 0;
        (ok && r.rlim_cur != libc::RLIM_INFINITY).then_some(r.rlim_cur)
    }
    #[cfg(not(unix))]
    {
        None
    }
}

fn total_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// The last-level cache's size (`/sys/devices/system/cpu/cpu0/cache/index3/size`), 32 MiB
/// where unknown.
fn last_level_cache() -> u64 {
    std::fs::read_to_string("/sys/devices/system/cpu/cpu0/cache/index3/size")
        .ok()
        .and_then(|s| {
            let t = s.trim();
            let (num, scale) = match t.strip_suffix('K') {
                Some(k) => (k, 1024),
                None => match t.strip_suffix('M') {
                    Some(m) => (m, 1 << 20),
                    None => (t, 1),
                },
            };
            num.parse::<u64>().ok().map(|v| v * scale)
        })
        .unwrap_or(32 << 20)
}

/// Field `k` of `/proc/self/statm` in bytes, 0 where unknown.
fn statm(k: usize) -> u64 {
    let page = 4096u64;
    std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(k).and_then(|p| p.parse::<u64>().ok()))
        .map_or(0, |pages| pages * page)
}

/// The process's resident memory now (`/proc/self/statm`), 0 where unknown.
pub fn resident() -> u64 {
    statm(1)
}

/// The process's address space now (every mapping, `/proc/self/statm`), 0 where unknown.
pub fn address_space() -> u64 {
    statm(0)
}

/// The process's peak resident memory so far (`VmHWM` of `/proc/self/status`), 0 where unknown.
pub fn peak_resident() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            let line = s.lines().find(|l| l.starts_with("VmHWM:"))?.to_string();
            line.split_whitespace().nth(1)?.parse::<u64>().ok()
        })
        .map_or(0, |kib| kib * 1024)
}

/// The error of a route whose predicted peak passes the budget: exit 3, with the estimate,
/// the budget and where the budget comes from.
pub fn over_budget(what: &str, predicted: u64, budget: &Budget) -> Error {
    Error::Memory {
        path: None,
        message: format!(
            "{what} would need about {} at its peak, over the memory budget of {} ({}); give a larger \
             --memory-limit if the machine has it, or a smaller input",
            size_text(predicted),
            size_text(budget.bytes),
            budget.source
        ),
        predicted,
        budget: budget.bytes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_as_people_write_them() {
        assert_eq!(parse_size("1024").unwrap(), 1024);
        assert_eq!(parse_size("2k").unwrap(), 2048);
        assert_eq!(parse_size("512 MiB").unwrap(), 512 << 20);
        assert_eq!(parse_size("6GB").unwrap(), 6 << 30);
        assert_eq!(parse_size("0.5t").unwrap(), 1 << 39);
        for bad in ["", "G", "-1G", "0", "6X", "nan G", "1e400"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
        assert_eq!(size_text(312 << 20), "312 MiB");
    }

    #[test]
    fn the_machine_s_budget_is_positive_and_this_process_is_resident() {
        let b = machine_budget();
        assert!(b.bytes > 0 && !b.source.is_empty());
        if cfg!(target_os = "linux") {
            let r = resident();
            assert!(r > 0 && peak_resident() >= r, "{r}");
        }
        let b = Budget { bytes: 6 << 30, source: "x".into(), address_space: false };
        let e = over_budget("the interior-point route", 17 << 30, &b);
        assert_eq!(e.exit_code(), 3);
        assert!(e.to_string().contains("17.00 GiB") && e.to_string().contains("6.00 GiB"), "{e}");
    }
}
