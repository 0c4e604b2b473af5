//! What the machine offers, read from the kernel's plain-text files: the
//! memory a request may use, so that engines refuse one too large before
//! allocating (rather than abort on a failed allocation); and the request
//! to stop that a signal makes.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

/// Bytes of memory available to a new allocation (Linux `MemAvailable` in
/// /proc/meminfo), or `None` where that cannot be read.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    parse_available(&text)
}

fn parse_available(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// A byte count for people: "512 B", "3.4 MB", "11.2 TB" (powers of 1000).
pub fn human_bytes(bytes: f64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut x = bytes;
    let mut k = 0;
    while x >= 1000.0 && k + 1 < units.len() {
        x /= 1000.0;
        k += 1;
    }
    if k == 0 {
        format!("{x:.0} B")
    } else {
        format!("{x:.1} {}", units[k])
    }
}

/// A number as people write it: plain between 10⁻⁴ and 10⁶, else with an
/// exponent (`1e-300` and `1e308`, not hundreds of digits).
pub fn human_number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `Err(message)` when `bytes` (a lower bound of what `what` needs) exceeds
/// the available memory; the message gives both numbers.
pub fn check_fits(what: &str, bytes: f64) -> Result<(), String> {
    match available_memory() {
        Some(free) if bytes > free as f64 => Err(format!(
            "{what} needs at least {}, and this machine has {} available",
            human_bytes(bytes),
            human_bytes(free as f64)
        )),
        _ => Ok(()),
    }
}

/// Bytes free to an unprivileged writer on the file system holding `dir`
/// (`statvfs`: f_bavail × f_frsize), or `None` where that cannot be read
/// or the file system has no blocks at all (/proc, /sys: there writing
/// fails for its own reason, which the writer reports).
pub fn free_disk(dir: &std::path::Path) -> Option<u64> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let path = std::ffi::CString::new(dir.as_os_str().as_bytes()).ok()?;
        let mut stat = std::mem::MaybeUninit::<libc::statvfs>::zeroed();
        // SAFETY: a NUL-terminated path and a buffer of the struct's size.
        let rc = unsafe { libc::statvfs(path.as_ptr(), stat.as_mut_ptr()) };
        if rc != 0 {
            return None;
        }
        // SAFETY: statvfs succeeded and filled it.
        let stat = unsafe { stat.assume_init() };
        if stat.f_blocks == 0 {
            return None;
        }
        // The fields' widths differ between platforms (u32 on some).
        #[allow(clippy::unnecessary_cast)]
        let (blocks, size) = (stat.f_bavail as u64, stat.f_frsize as u64);
        Some(blocks.saturating_mul(size))
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        None
    }
}

/// A request to stop the run in progress, by signal number (SIGINT 2,
/// SIGTERM 15; 0: none). Signal handlers set it (async-signal-safe: one
/// atomic store); every engine's loop reads it once a step and then ends
/// the run cleanly: files flushed, a final checkpoint where checkpoints are
/// on.
pub fn stop_flag() -> &'static Arc<AtomicUsize> {
    static FLAG: OnceLock<Arc<AtomicUsize>> = OnceLock::new();
    FLAG.get_or_init(|| Arc::new(AtomicUsize::new(0)))
}

/// The signal that asked the run to stop, if one did.
pub fn stop_requested() -> Option<i32> {
    match stop_flag().load(Ordering::Relaxed) {
        0 => None,
        s => Some(s as i32),
    }
}

/// Asks the run in progress to stop as if signal `signal` had come.
pub fn request_stop(signal: i32) {
    stop_flag().store(signal as usize, Ordering::Relaxed);
}

/// Hands freed heap pages back to the system (glibc's `malloc_trim`, which
/// also releases whole free pages inside the heap). A trajectory frame of
/// 10⁶ particles is a transient copy with one small allocation per species
/// name; freed, those chunks stay resident wherever later allocations pin
/// the heap, so a long run's resident memory steps up by the size of a
/// frame once (61 MiB at 10⁶ spheres in the granular soak) unless they are
/// given back. A no-op elsewhere.
pub fn release_free_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only returns free memory of the allocator's own
    // arenas to the kernel; it touches no live allocation.
    unsafe {
        libc::malloc_trim(0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_available_memory_and_prints_bytes() {
        let info = "MemTotal:       24000000 kB\nMemFree:  100 kB\nMemAvailable:   23000000 kB\n";
        assert_eq!(parse_available(info), Some(23_000_000 * 1024));
        assert_eq!(parse_available("MemTotal: 5 kB\n"), None);
        assert_eq!(human_bytes(512.0), "512 B");
        assert_eq!(human_bytes(3.4e6), "3.4 MB");
        assert_eq!(human_bytes(1.12e13), "11.2 TB");
        assert!(check_fits("a request", 1e30)
            .unwrap_err()
            .contains("needs at least"));
        assert!(check_fits("a request", 1.0).is_ok());
    }
}
