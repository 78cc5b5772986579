//! A render's peak memory, estimated before rendering, and the memory there is to hold it.
//!
//! ```text
//! peak ≈ base + scene + threads·workspace
//!        + pixels·(12 film + 3 if 8-bit + 12 if EXR to a stream + 48 with a cost map)
//! ```
//!
//! Figures (`/usr/bin/time -v`, max RSS, built-in box, `--shadows off --bounces 0`, 2 threads)
//! are in the reliability notes; the estimate is an upper bound of each within about 25 %.

use anyhow::{Result, bail};

/// Bytes per pixel of the linear film (three `f32`).
const FILM_BYTES_PER_PIXEL: u64 = 12;
/// Bytes per pixel of the tone-mapped 8-bit copy.
const RGB8_BYTES_PER_PIXEL: u64 = 3;
/// The process before any image: code, the thread pool, stacks, the scene's small arrays
/// (a 512² PFM render peaks at 10.9 MiB, of which 3 MiB is the film).
const BASE_BYTES: u64 = 8 << 20;
/// Per pixel, for encoder buffers and the allocator's rounding: keeps the estimate above the
/// measured peaks (PNG at 4096² was within 1 % of film + 8-bit copy + base).
const SLACK_BYTES_PER_PIXEL: u64 = 1;
/// Per triangle or sphere, the scene arrays and both engines' BVH copies.
const BYTES_PER_PRIMITIVE: u64 = 400;
/// Per camera sample of a wavefront tile (rays, hits, shadow queue, radiance, next rays).
const WORKSPACE_BYTES_PER_SAMPLE: u64 = 512;
/// Per pixel for `--cost-map`: its counts by kind (36 bytes), the map's values (4) and the
/// figure's pixels, two panels of 3 bytes.
const COST_MAP_BYTES_PER_PIXEL: u64 = 48;

/// What a render holds at its peak.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderFootprint {
    /// Image width × height.
    pub pixels: u64,
    /// Triangles plus spheres.
    pub primitives: u64,
    /// Worker threads.
    pub threads: u64,
    /// Camera samples per wavefront tile.
    pub batch_size: u64,
    /// An 8-bit image is made (PNG or PPM output).
    pub rgb8: bool,
    /// An EXR goes to a stream (stdout, a FIFO) and is encoded in memory first.
    pub exr_in_memory: bool,
    /// A cost map is drawn (`render --cost-map`): each pixel's traversal counts are kept.
    pub cost_map: bool,
}

impl RenderFootprint {
    /// The estimated peak in bytes: an upper bound of the measured peak.
    fn peak_bytes(&self) -> u64 {
        let per_pixel = FILM_BYTES_PER_PIXEL
            + SLACK_BYTES_PER_PIXEL
            + u64::from(self.rgb8) * RGB8_BYTES_PER_PIXEL
            + u64::from(self.exr_in_memory) * 12
            + u64::from(self.cost_map) * COST_MAP_BYTES_PER_PIXEL;
        BASE_BYTES
            + self.primitives * BYTES_PER_PRIMITIVE
            + self.threads * self.batch_size * WORKSPACE_BYTES_PER_SAMPLE
            + self.pixels * per_pixel
    }
}

/// Refuses a render whose estimated peak exceeds `--max-memory` or the memory available
/// (MemAvailable, and the cgroup's limit when one is set).
pub fn check(footprint: &RenderFootprint, max_memory: Option<u64>) -> Result<()> {
    let need = footprint.peak_bytes();
    if let Some(max) = max_memory
        && need > max
    {
        bail!(
            "this render needs about {} of memory, more than --max-memory {}: use a smaller --size or raise --max-memory",
            format_bytes(need),
            format_bytes(max)
        );
    }
    if let Some((have, source)) = available()
        && need > have
    {
        bail!(
            "this render needs about {} of memory and only {} is available ({source}): use a smaller --size",
            format_bytes(need),
            format_bytes(have)
        );
    }
    Ok(())
}

/// The memory this process may still use, and where the figure comes from.
pub fn available() -> Option<(u64, &'static str)> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok().and_then(|t| {
        t.lines()
            .find_map(|l| l.strip_prefix("MemAvailable:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
            .map(|kb| (kb * 1024, "MemAvailable in /proc/meminfo"))
    });
    // The smaller; MemAvailable's on a tie.
    [meminfo, cgroup_limit()]
        .into_iter()
        .flatten()
        .min_by_key(|&(bytes, _)| bytes)
}

/// The cgroup's memory limit less its usage (v2 `memory.max`, v1 `memory.limit_in_bytes`).
fn cgroup_limit() -> Option<(u64, &'static str)> {
    let read = |p: &str| -> Option<u64> { std::fs::read_to_string(p).ok()?.trim().parse().ok() };
    let candidates = [
        (
            "/sys/fs/cgroup/memory.max",
            "/sys/fs/cgroup/memory.current",
            "the cgroup's memory.max",
        ),
        (
            "/sys/fs/cgroup/memory/memory.limit_in_bytes",
            "/sys/fs/cgroup/memory/memory.usage_in_bytes",
            "the cgroup's memory.limit_in_bytes",
        ),
    ];
    candidates.iter().find_map(|(limit, usage, name)| {
        // "max", or v1's "no limit" (a page-rounded i64::MAX), mean unlimited.
        let limit = read(limit).filter(|&l| l < 1 << 60)?;
        Some((limit.saturating_sub(read(usage).unwrap_or(0)), *name))
    })
}

/// Parses `2G`, `512M`, `64k`, `1.5GiB` or a plain number of bytes (powers of 1024).
pub fn parse_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let shift = match unit.to_ascii_lowercase().as_str() {
        "" | "b" => 0,
        "k" | "kb" | "kib" => 10,
        "m" | "mb" | "mib" => 20,
        "g" | "gb" | "gib" => 30,
        "t" | "tb" | "tib" => 40,
        _ => return Err(format!("expected a size such as 512M or 2G, found `{s}`")),
    };
    match number.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 && x * ((1u64 << shift) as f64) < 1.8e19 => {
            Ok((x * (1u64 << shift) as f64) as u64)
        }
        _ => Err(format!(
            "expected a positive size such as 512M or 2G, found `{s}`"
        )),
    }
}

/// Bytes for people: `1.5 GiB`, `300 MiB`.
fn format_bytes(bytes: u64) -> String {
    let mib = bytes as f64 / (1u64 << 20) as f64;
    if mib >= 1024.0 {
        format!("{:.1} GiB", mib / 1024.0)
    } else {
        format!("{mib:.0} MiB")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Max RSS in KiB from `/usr/bin/time -f %M raywave render --size N N --shadows off
    /// --bounces 0 -q -o FILE` on 2 threads: (N, 8-bit output, KiB).
    const MEASURED: [(u64, bool, u64); 8] = [
        (512, true, 11_624),
        (512, false, 12_156),
        (2048, true, 69_692),
        (2048, false, 58_268),
        (4096, true, 254_768),
        (4096, false, 205_912),
        (8192, true, 993_752),
        (8192, false, 796_088),
    ];

    #[test]
    fn the_estimate_bounds_the_measured_peaks_within_25_percent_from_2048_up() {
        for (n, rgb8, kib) in MEASURED {
            let estimate = RenderFootprint {
                pixels: n * n,
                primitives: 12,
                threads: 2,
                batch_size: 4096,
                rgb8,
                exr_in_memory: false,
                cost_map: false,
            }
            .peak_bytes();
            let measured = kib * 1024;
            assert!(estimate >= measured, "{n}² {rgb8}: {estimate} < {measured}");
            if n >= 2048 {
                assert!(
                    estimate * 4 <= measured * 5,
                    "{n}² {rgb8}: {estimate} ≫ {measured}"
                );
            }
        }
    }

    #[test]
    fn sizes_parse_in_powers_of_1024() {
        assert_eq!(parse_size("2G"), Ok(2 << 30));
        assert_eq!(parse_size("512M"), Ok(512 << 20));
        assert_eq!(parse_size("1.5GiB"), Ok(3 << 29));
        assert_eq!(parse_size("4096"), Ok(4096));
        for bad in ["", "G", "-1G", "0", "2X", "nan", "1e400"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }
}
