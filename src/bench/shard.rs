//! `raywave bench --shard I/N --out DIR`: one job's share of a sweep, and the part file it
//! leaves for `raywave bench merge` (merge.rs). Each job computes the whole sweep's identity
//! and the same split, benches only its own points, and writes one self-describing file.
//!
//! ```text
//! cost(point) = width · height · (1 + lights · shadow rays per light) · (runs + warm-up) / threads
//! split:      output::shard::partition(costs, N): longest first, to the least-loaded shard
//! part file:  DIR/bench-shard-I-of-N.json, written whole or not at all (temp + rename)
//!   { "format": "raywave-bench-shard", "version": 1,
//!     "checksum": "fnv1a64:HEX"          FNV-1a of the payload's bytes exactly as written
//!     "payload": { sweep, shard, points, labels, host, started, finished, seconds, records } }
//! ```
//!
//! A part is read back only whole and intact: JSON that does not parse (a truncated file), a
//! checksum that does not match the payload's bytes (an edited or damaged file), another format
//! or version, or a payload that contradicts itself (points that are not this shard's share,
//! records of other settings or another build) is refused with the file's name.

use crate::output::bench_record::{self as record, BenchRecord, Setup};
use crate::output::build_info::BuildInfo;
use crate::output::machine::Machine;
use crate::output::shard::Shard;
use crate::render::settings::ShadowMode;
use anyhow::{Context, Result, bail};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The `format` of a part file.
pub const PART_FORMAT: &str = "raywave-bench-shard";

/// The layout version of part files, bumped when the payload's layout changes.
pub(crate) const PART_VERSION: u32 = 1;

/// The largest part file `read_part` reads (a record of 1000 runs is about 1 MiB).
pub(crate) const MAX_PART_BYTES: u64 = 512 << 20;

/// The estimated cost of timing one point: the rays its renders cast (camera rays, and a
/// shadow ray per light and shadow point, at every pixel; bounces and anti-aliasing are the
/// same at every point of a sweep), over all warm-up and timed runs, per worker thread, since
/// a point on one thread takes about twice as long as on two.
pub fn cost(setup: &Setup, runs: u32, warmup: u32) -> f64 {
    let s = &setup.settings;
    let per_light = match s.shadows {
        ShadowMode::Off => 0,
        ShadowMode::Hard => 1,
        ShadowMode::Soft => u64::from(s.shadow_samples),
    };
    let per_pixel = 1 + setup.scene.lights as u64 * per_light;
    let rays = u64::from(s.width) as f64
        * f64::from(s.height)
        * per_pixel as f64
        * f64::from(runs + warmup);
    rays / setup.threads.max(1) as f64
}

/// What makes a sweep the same sweep: the build that timed it, the engines, the run counts,
/// and every point's setup (scene, with its text's hash; settings; threads; batch size). Every
/// shard of one sweep carries an equal identity.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SweepIdentity {
    /// raywave's version.
    pub raywave: String,
    /// The build: commit, dirty flag, profile, target, target features, RUSTFLAGS.
    pub build: BuildInfo,
    /// The SIMD path of the wavefront engine (`raywave::simd_path_for` its `--lanes`).
    pub simd: String,
    /// The engines timed, in record order.
    pub engines: Vec<String>,
    /// Timed runs per engine.
    pub runs: u32,
    /// Untimed runs per engine before the timed ones.
    pub warmup: u32,
    /// Every point of the sweep, in sweep order (sizes outermost, threads innermost).
    pub points: Vec<SweepPoint>,
}

/// One point of a sweep, as its identity holds it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SweepPoint {
    /// The swept values, `16x16+t1`; empty for a sweep of one point.
    pub label: String,
    /// Scene, settings, threads, batch size.
    pub setup: Setup,
    /// The estimated cost ([`cost`]) the split is made by.
    pub cost: f64,
}

impl SweepIdentity {
    /// The costs of the points, in sweep order.
    pub fn costs(&self) -> Vec<f64> {
        self.points.iter().map(|p| p.cost).collect()
    }

    /// How `other` differs from this identity, one line per difference (empty: the same
    /// sweep), the sides named `a` and `b`. The build is compared by [`Self::build_differences`];
    /// scene file names are not compared (their text's hash is).
    pub fn sweep_differences(&self, other: &SweepIdentity, a: &str, b: &str) -> Vec<String> {
        let mut out = Vec::new();
        let mut field = |name: &str, x: String, y: String| {
            if x != y {
                out.push(format!("{name}: {x} {a}, {y} {b}"));
            }
        };
        field("engines", self.engines.join(","), other.engines.join(","));
        field("runs", self.runs.to_string(), other.runs.to_string());
        field("warmup", self.warmup.to_string(), other.warmup.to_string());
        let labels = |s: &SweepIdentity| {
            let v: Vec<&str> = s.points.iter().map(|p| p.label.as_str()).collect();
            format!("[{}]", v.join(", "))
        };
        field("points", labels(self), labels(other));
        if out.is_empty() {
            for (p, q) in self.points.iter().zip(&other.points) {
                for d in super::compare::setup_differences_as(&p.setup, &q.setup, a, b) {
                    let at = if p.label.is_empty() {
                        "point"
                    } else {
                        &p.label
                    };
                    out.push(format!("{at}: {d}"));
                }
            }
        }
        out
    }

    /// How the build of `other` differs from this one's (version, every build field, SIMD
    /// path), one line each.
    pub fn build_differences(&self, other: &SweepIdentity, a: &str, b: &str) -> Vec<String> {
        let describe = |s: &SweepIdentity| {
            [
                ("raywave", s.raywave.clone()),
                ("commit", s.build.short_commit()),
                ("profile", s.build.profile.clone()),
                ("target", s.build.target.clone()),
                ("target features", s.build.target_features.clone()),
                ("RUSTFLAGS", s.build.rustflags.clone()),
                ("simd", s.simd.clone()),
            ]
        };
        describe(self)
            .into_iter()
            .zip(describe(other))
            .filter(|((_, x), (_, y))| x != y)
            .map(|((name, x), (_, y))| format!("{name}: {x} {a}, {y} {b}"))
            .collect()
    }
}

/// What one shard ran: the part file's payload.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Part {
    /// The whole sweep's identity, equal in every shard of it.
    pub sweep: SweepIdentity,
    /// Which shard this is.
    pub shard: Shard,
    /// The points it ran, as indices into `sweep.points`, ascending.
    pub points: Vec<usize>,
    /// Their labels.
    pub labels: Vec<String>,
    /// The machine it ran on.
    pub host: Machine,
    /// When its first point started, UTC, RFC 3339 with milliseconds.
    pub started: String,
    /// When its last point ended.
    pub finished: String,
    /// Wall-clock seconds from start to end.
    pub seconds: f64,
    /// One record per point it ran, in the order of `points`.
    pub records: Vec<BenchRecord>,
}

/// A part file of `raywave bench --shard I/N --out DIR`: what the shard ran, and the checksum
/// of those bytes as written. (The type gives the JSON Schema; the payload itself is written
/// and read as raw bytes, so that the checksum covers exactly them.)
#[derive(Serialize, Deserialize, JsonSchema)]
pub(crate) struct PartFile {
    /// Always `raywave-bench-shard`.
    #[schemars(extend("const" = PART_FORMAT))]
    pub format: String,
    /// The layout version, bumped when the payload's layout changes.
    #[schemars(extend("const" = PART_VERSION))]
    pub version: u32,
    /// `fnv1a64:` and the 16 hex digits of FNV-1a (64-bit) of the payload's bytes as written.
    #[schemars(regex(pattern = r"^fnv1a64:[0-9a-f]{16}$"))]
    pub checksum: String,
    /// What the shard ran.
    pub payload: Part,
}

/// The part file as read: the payload kept as the bytes that were hashed.
#[derive(Serialize, Deserialize)]
struct Envelope<'a> {
    format: String,
    version: u32,
    checksum: String,
    #[serde(borrow)]
    payload: &'a RawValue,
}

/// The file name of `shard`'s part: `bench-shard-I-of-N.json`.
pub fn part_name(shard: Shard) -> String {
    format!("bench-shard-{}-of-{}.json", shard.index, shard.count)
}

/// The checksum of a payload's bytes, as part files spell it.
fn checksum(payload: &str) -> String {
    format!("fnv1a64:{}", crate::render::digest::hex(payload.as_bytes()))
}

/// Writes `part` to `dir`/[`part_name`] atomically, creating `dir`; returns the path.
pub fn write_part(dir: &Path, part: &Part) -> Result<PathBuf> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create directory {}", dir.display()))?;
    let path = dir.join(part_name(part.shard));
    // Indented to sit inside the envelope: JSON strings escape their line breaks, so every raw
    // one is layout.
    let payload = serde_json::to_string_pretty(part)?.replace('\n', "\n  ");
    let envelope = Envelope {
        format: PART_FORMAT.to_string(),
        version: PART_VERSION,
        checksum: checksum(&payload),
        payload: &RawValue::from_string(payload)?,
    };
    crate::output::image_file::write_atomically(&path, |w| {
        serde_json::to_writer_pretty(&mut *w, &envelope)?;
        Ok(writeln!(w)?)
    })?;
    Ok(path)
}

/// Reads a part file, refusing (with its name) one that is not whole, not intact or not
/// consistent with itself.
pub fn read_part(path: &Path) -> Result<Part> {
    let shown = path.display();
    let meta = std::fs::metadata(path).with_context(|| format!("cannot read {shown}"))?;
    // A FIFO would hang the merge and a link to /dev/zero read until memory runs out.
    if !meta.is_file() {
        bail!(
            "{shown}: expected a bench shard file (a regular JSON file), found a directory or device"
        );
    }
    if meta.len() > MAX_PART_BYTES {
        bail!(
            "{shown}: {} bytes, expected a bench shard file of at most {} MiB",
            meta.len(),
            MAX_PART_BYTES >> 20
        );
    }
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {shown}"))?;
    let envelope: Envelope = serde_json::from_str(&text).map_err(|e| {
        anyhow::anyhow!(
            "{shown}: not a whole bench shard file ({e}): truncated, or not written by \
             `raywave bench --shard I/N --out DIR`; run that shard again"
        )
    })?;
    if envelope.format != PART_FORMAT {
        bail!(
            "{shown}: format `{}`, expected `{PART_FORMAT}` (a file of `raywave bench --shard`)",
            envelope.format.escape_debug()
        );
    }
    if envelope.version != PART_VERSION {
        bail!(
            "{shown}: bench shard version {}, expected {PART_VERSION}: run the shard again \
             with this build",
            envelope.version
        );
    }
    let found = checksum(envelope.payload.get());
    if found != envelope.checksum {
        bail!(
            "{shown}: checksum mismatch (the file says {}, its payload hashes to {found}): it \
             was changed or damaged after it was written; run that shard again",
            envelope.checksum.escape_debug()
        );
    }
    let part: Part = serde_json::from_str(envelope.payload.get())
        .with_context(|| format!("{shown}: not a valid bench shard payload"))?;
    if let Some(problem) = inconsistency(&part) {
        bail!("{shown}: inconsistent bench shard file: {problem}");
    }
    Ok(part)
}

/// The first way `part` contradicts itself, if any.
fn inconsistency(part: &Part) -> Option<String> {
    let Shard { index, count } = part.shard;
    if count == 0 || index >= count || count > crate::output::shard::MAX_SHARDS {
        return Some(format!(
            "shard {index}/{count}, expected I < N <= {}",
            crate::output::shard::MAX_SHARDS
        ));
    }
    if part.sweep.points.is_empty() {
        return Some("a sweep of no points, expected at least one".into());
    }
    let expected = part.shard.items(&part.sweep.costs());
    if part.points != expected {
        return Some(format!(
            "it ran points {:?}, but shard {} of this sweep is points {expected:?}",
            part.points, part.shard
        ));
    }
    if part.labels.len() != part.points.len() || part.records.len() != part.points.len() {
        return Some(format!(
            "{} point(s), {} label(s) and {} record(s), expected as many of each",
            part.points.len(),
            part.labels.len(),
            part.records.len()
        ));
    }
    for ((&i, label), r) in part.points.iter().zip(&part.labels).zip(&part.records) {
        let point = &part.sweep.points[i];
        if *label != point.label {
            return Some(format!(
                "point {i} is labelled `{label}`, expected `{}`",
                point.label
            ));
        }
        let at = if label.is_empty() { "the point" } else { label };
        if r.format != record::FORMAT {
            return Some(format!(
                "{at}: record format {}, expected {}",
                r.format,
                record::FORMAT
            ));
        }
        if r.setup != point.setup {
            return Some(format!("{at}: the record's setup is not the sweep's"));
        }
        if (&r.raywave, &r.build, &r.simd)
            != (&part.sweep.raywave, &part.sweep.build, &part.sweep.simd)
        {
            return Some(format!("{at}: the record's build is not the sweep's"));
        }
        if (r.runs, r.warmup) != (part.sweep.runs, part.sweep.warmup) {
            return Some(format!("{at}: the record's run counts are not the sweep's"));
        }
    }
    None
}

/// Now, UTC, RFC 3339 with milliseconds (a part's `started` and `finished`).
pub fn now_millis() -> String {
    humantime::format_rfc3339_millis(std::time::SystemTime::now()).to_string()
}

/// The JSON Schema of part files (docs/schema/bench-shard.schema.json), generated from
/// [`PartFile`] as the record schemas are (`output::render_record::schemas`).
pub fn schema() -> String {
    let generator = schemars::generate::SchemaSettings::draft2020_12()
        .for_serialize()
        .into_generator();
    let mut text = serde_json::to_string_pretty(&generator.into_root_schema_for::<PartFile>())
        .unwrap_or_default();
    text.push('\n');
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::bench_record::SceneId;
    use crate::render::settings::RenderSettings;

    fn setup(width: u32, shadows: ShadowMode, samples: u32, threads: usize) -> Setup {
        Setup {
            scene: SceneId {
                source: "s.obj".into(),
                text_hash: "0123456789abcdef".into(),
                triangles: 2,
                spheres: 0,
                lights: 3,
            },
            settings: RenderSettings {
                width,
                height: 10,
                shadows,
                shadow_samples: samples,
                ..RenderSettings::default()
            },
            threads,
            batch_size: 64,
        }
    }

    #[test]
    fn the_cost_counts_rays_of_every_run_per_thread() {
        // 20 × 10 pixels, (1 camera + 3 lights × 4 points) rays each, 6 + 1 runs, 2 threads.
        let soft = cost(&setup(20, ShadowMode::Soft, 4, 2), 6, 1);
        assert_eq!(soft, 200.0 * 13.0 * 7.0 / 2.0);
        assert_eq!(cost(&setup(20, ShadowMode::Soft, 4, 1), 6, 1), 2.0 * soft);
        assert_eq!(
            cost(&setup(20, ShadowMode::Hard, 4, 1), 6, 1),
            200.0 * 4.0 * 7.0
        );
        assert_eq!(cost(&setup(20, ShadowMode::Off, 4, 1), 6, 1), 200.0 * 7.0);
    }

    /// A part of a sweep of three points (costs 3, 2, 1 by width) as shard `index` of 3,
    /// without records: each point's is left out, so only an empty shard is consistent.
    fn empty_part(index: usize) -> Part {
        let points = [30, 20, 10]
            .iter()
            .map(|&w| {
                let setup = setup(w, ShadowMode::Soft, 4, 1);
                SweepPoint {
                    label: format!("{w}x10"),
                    cost: cost(&setup, 6, 1),
                    setup,
                }
            })
            .collect();
        Part {
            sweep: SweepIdentity {
                raywave: "0.1.0".into(),
                build: crate::output::build_info::current(),
                simd: "scalar".into(),
                engines: vec!["wavefront".into()],
                runs: 6,
                warmup: 1,
                points,
            },
            shard: Shard { index, count: 4 },
            points: Vec::new(),
            labels: Vec::new(),
            host: Machine::current(),
            started: now_millis(),
            finished: now_millis(),
            seconds: 0.0,
            records: Vec::new(),
        }
    }

    fn error(path: &Path) -> String {
        format!("{:#}", read_part(path).unwrap_err())
    }

    #[test]
    fn a_part_reads_back_whole_and_intact_only() {
        let dir = tempfile::tempdir().unwrap();
        // Three points in four shards: shard 3 is empty.
        let part = empty_part(3);
        let path = write_part(dir.path(), &part).unwrap();
        assert_eq!(path, dir.path().join("bench-shard-3-of-4.json"));
        assert_eq!(read_part(&path).unwrap(), part);
        let text = std::fs::read_to_string(&path).unwrap();

        std::fs::write(&path, &text[..text.len() - 10]).unwrap();
        assert!(
            error(&path).contains("not a whole bench shard file"),
            "{}",
            error(&path)
        );
        std::fs::write(&path, text.replacen("30x10", "31x10", 1)).unwrap();
        assert!(
            error(&path).contains("checksum mismatch"),
            "{}",
            error(&path)
        );
        std::fs::write(&path, text.replacen("\"version\": 1", "\"version\": 2", 1)).unwrap();
        assert!(
            error(&path).contains("version 2, expected 1"),
            "{}",
            error(&path)
        );
        std::fs::write(&path, text.replacen(PART_FORMAT, "raywave-bench", 1)).unwrap();
        assert!(
            error(&path).contains("expected `raywave-bench-shard`"),
            "{}",
            error(&path)
        );
        assert!(error(dir.path()).contains("found a directory"));

        // Shard 0 of this sweep is its dearest point: a file that claims none is refused,
        // checksum and all.
        let liar = empty_part(0);
        let path = write_part(dir.path(), &liar).unwrap();
        let e = error(&path);
        assert!(
            e.contains("inconsistent") && e.contains("is points [0]"),
            "{e}"
        );
    }
}
