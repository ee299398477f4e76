//! The memory a run may use, read before it allocates: the least of what the
//! machine has available, what the process's cgroup has left, and what the
//! address-space limit (`ulimit -v`) leaves, each where this system tells it.

/// Of the address space left under `ulimit -v`, the share a run may count on
/// for its data: the rest goes to what an estimate of resident memory does
/// not see (thread stacks, the allocator's reserved arenas, the binary).
pub const ADDRESS_SPACE_SHARE: f64 = 0.8;

/// How much memory a run may use, MB, and what sets it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MemoryBudget {
    /// Megabytes.
    pub mb: f64,
    /// What sets it, for messages: "the memory this machine has available", …
    pub source: &'static str,
}

/// The memory a run may use now: the least of the machine's `MemAvailable`,
/// the cgroup's limit less its use, and [`ADDRESS_SPACE_SHARE`] of the
/// address-space limit less what the process has mapped (`None` when the
/// system tells none of them).
pub fn memory_budget() -> Option<MemoryBudget> {
    let read = |path: &str| std::fs::read_to_string(path).ok();
    budget_of(&Sources {
        meminfo: read("/proc/meminfo"),
        limits: read("/proc/self/limits"),
        status: read("/proc/self/status"),
        cgroup_max: read("/sys/fs/cgroup/memory.max")
            .or_else(|| read("/sys/fs/cgroup/memory/memory.limit_in_bytes")),
        cgroup_current: read("/sys/fs/cgroup/memory.current")
            .or_else(|| read("/sys/fs/cgroup/memory/memory.usage_in_bytes")),
    })
}

/// Refuses, in one line, to read `what` when holding it is estimated to need
/// more than [`memory_budget`]: `bytes` on disk, `factor` bytes in memory for
/// each (text and what it is parsed into).
pub fn check_reading(what: &str, bytes: u64, factor: f64) -> anyhow::Result<()> {
    const MB: f64 = 1024.0 * 1024.0;
    check_needed(
        &format!("reading {what} ({} MB on disk)", (bytes as f64 / MB).ceil()),
        bytes as f64 * factor / MB,
        0.0,
        "",
    )
}

/// Refuses, in one line, `what` estimated to need `needed_mb` when that is
/// more than `configured_mb` (`limits.max_memory_mb`; 0: none) or, without
/// it, [`memory_budget`]; `hint` (if any) says what to change.
pub fn check_needed(
    what: &str,
    needed_mb: f64,
    configured_mb: f64,
    hint: &str,
) -> anyhow::Result<()> {
    let (limit, source) = if configured_mb > 0.0 {
        (configured_mb, "`limits.max_memory_mb`")
    } else {
        match memory_budget() {
            Some(b) => (b.mb, b.source),
            None => return Ok(()),
        }
    };
    if needed_mb > limit {
        let hint = if hint.is_empty() {
            String::new()
        } else {
            format!("; {hint}")
        };
        anyhow::bail!(
            "{what} is estimated to need {} MB, more than {source} ({} MB){hint}",
            needed_mb.ceil(),
            limit.floor()
        );
    }
    Ok(())
}

/// The texts the budget is read from.
#[derive(Debug, Default)]
struct Sources {
    meminfo: Option<String>,
    limits: Option<String>,
    status: Option<String>,
    cgroup_max: Option<String>,
    cgroup_current: Option<String>,
}

/// The budget the texts of `s` give.
fn budget_of(s: &Sources) -> Option<MemoryBudget> {
    const MB: f64 = 1024.0 * 1024.0;
    let mut all = Vec::new();
    if let Some(kb) = s.meminfo.as_deref().and_then(|t| kb_of(t, "MemAvailable:")) {
        all.push(MemoryBudget {
            mb: kb as f64 / 1024.0,
            source: "the memory this machine has available",
        });
    }
    let max = s.cgroup_max.as_deref().and_then(bytes_of);
    let current = s.cgroup_current.as_deref().and_then(bytes_of);
    if let (Some(max), Some(current)) = (max, current) {
        // cgroup v1 tells "no limit" as a number near 2^63.
        if max < 1 << 60 {
            all.push(MemoryBudget {
                mb: max.saturating_sub(current) as f64 / MB,
                source: "the memory limit of this process's cgroup, less its use",
            });
        }
    }
    let limit = s.limits.as_deref().and_then(address_space_limit);
    let mapped = s.status.as_deref().and_then(|t| kb_of(t, "VmSize:"));
    if let (Some(limit), Some(mapped)) = (limit, mapped) {
        all.push(MemoryBudget {
            mb: ADDRESS_SPACE_SHARE * limit.saturating_sub(mapped.saturating_mul(1024)) as f64 / MB,
            source: "the address-space limit (ulimit -v) left to this process",
        });
    }
    all.into_iter().min_by(|a, b| a.mb.total_cmp(&b.mb))
}

/// The value of the line starting with `key` of a `/proc` text, kB.
pub(crate) fn kb_of(text: &str, key: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(key))?;
    let mut words = line[key.len()..].split_whitespace();
    let kb = words.next()?.parse().ok()?;
    (words.next() == Some("kB")).then_some(kb)
}

/// A cgroup file's byte count (`None` for `max`, no limit).
fn bytes_of(text: &str) -> Option<u64> {
    text.trim().parse().ok()
}

/// The soft address-space limit of a `/proc/self/limits` text, bytes (`None`
/// when unlimited).
fn address_space_limit(limits: &str) -> Option<u64> {
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    line["Max address space".len()..]
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    const MEMINFO: &str =
        "MemTotal:       24000000 kB\nMemFree:  100 kB\nMemAvailable:   20480000 kB\n";
    const STATUS: &str =
        "Name:\tcpsplan\nVmPeak:\t  300000 kB\nVmSize:\t  102400 kB\nVmHWM:\t   5000 kB\n";

    fn limits(soft: &str) -> String {
        format!(
            "Limit                     Soft Limit           Hard Limit           Units     \n\
             Max cpu time              unlimited            unlimited            seconds   \n\
             Max address space         {soft:<20} unlimited            bytes     \n\
             Max file locks            unlimited            unlimited            locks     \n"
        )
    }

    #[test]
    fn the_machine_sets_the_budget_without_other_limits() {
        let b = budget_of(&Sources {
            meminfo: Some(MEMINFO.into()),
            limits: Some(limits("unlimited")),
            status: Some(STATUS.into()),
            cgroup_max: Some("max\n".into()),
            cgroup_current: Some("1000000\n".into()),
        })
        .unwrap();
        assert_eq!(b.mb, 20_000.0);
        assert!(b.source.contains("machine"));
    }

    #[test]
    fn an_address_space_limit_binds_less_what_is_mapped() {
        // 4 GiB less 100 MiB mapped, 80 % of it.
        let b = budget_of(&Sources {
            meminfo: Some(MEMINFO.into()),
            limits: Some(limits("4294967296")),
            status: Some(STATUS.into()),
            ..Sources::default()
        })
        .unwrap();
        assert!((b.mb - 0.8 * (4096.0 - 100.0)).abs() < 1e-9, "{b:?}");
        assert!(b.source.contains("ulimit -v"));
    }

    #[test]
    fn a_cgroup_limit_binds_less_its_use() {
        let b = budget_of(&Sources {
            meminfo: Some(MEMINFO.into()),
            cgroup_max: Some("2147483648\n".into()),
            cgroup_current: Some("1073741824\n".into()),
            ..Sources::default()
        })
        .unwrap();
        assert_eq!(b.mb, 1024.0);
        assert!(b.source.contains("cgroup"));
        // cgroup v1's "no limit".
        let b = budget_of(&Sources {
            meminfo: Some(MEMINFO.into()),
            cgroup_max: Some("9223372036854771712\n".into()),
            cgroup_current: Some("1073741824\n".into()),
            ..Sources::default()
        })
        .unwrap();
        assert_eq!(b.mb, 20_000.0);
    }

    #[test]
    fn nothing_known_gives_no_budget() {
        assert_eq!(budget_of(&Sources::default()), None);
        assert_eq!(kb_of("MemAvailable: 12", "MemAvailable:"), None);
    }
}
