//! What machine a measurement ran on: host name, CPU model, logical CPUs. Shared by
//! `--stats-json` and `raywave bench`.

use serde::{Deserialize, Serialize};

/// The CPU's model name from /proc/cpuinfo, where there is one.
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".to_string())
}

/// The host name (Linux's /proc/sys/kernel/hostname, else /etc/hostname), or "unknown".
pub fn hostname() -> String {
    ["/proc/sys/kernel/hostname", "/etc/hostname"]
        .iter()
        .filter_map(|p| std::fs::read_to_string(p).ok())
        .map(|s| s.trim().to_string())
        .find(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".to_string())
}

/// Logical CPUs the process may use.
pub fn logical_cpus() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The machine a measurement ran on, as `--stats-json` files and bench records name it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Machine {
    /// Host name (empty, and then left out, in `--stats-json`, which has never named it).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub hostname: String,
    /// CPU model from /proc/cpuinfo.
    pub cpu: String,
    /// Logical CPUs available.
    pub logical_cpus: usize,
    /// `std::env::consts::OS`.
    pub os: String,
    /// `std::env::consts::ARCH`.
    pub arch: String,
}

impl Machine {
    /// This machine.
    pub fn current() -> Machine {
        Machine {
            hostname: hostname(),
            cpu: cpu_model(),
            logical_cpus: logical_cpus(),
            os: std::env::consts::OS.to_string(),
            arch: std::env::consts::ARCH.to_string(),
        }
    }
}
