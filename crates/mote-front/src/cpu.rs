//! CPU time of this process (user + system), for rates per CPU-second.

/// CPU seconds used so far, from /proc/self/stat (NaN where there is none).
pub fn cpu_seconds() -> f64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // The fields after `(comm)`: state is field 3, utime 14, stime 15.
    let Some(rest) = s.rfind(')').map(|k| &s[k + 2..]) else {
        return f64::NAN;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |k: usize| {
        f.get(k)
            .and_then(|x| x.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    // The kernel reports in USER_HZ, 100 on Linux.
    (ticks(11) + ticks(12)) / 100.0
}
