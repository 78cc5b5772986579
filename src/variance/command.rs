//! `raywave variance`: the study as a command (options, checks, outputs); the flags, the
//! progress bar and the printed table are the binary's (`cli/variance.rs`).

use super::report::summary::Summary;
use super::study::jobs::{self, CaseFacts, Job, JobResult, Setup};
use super::study::plan::{Case, Study, case_names, identity};
use super::{Cache, Region, RenderFn, StudyConfig};
use crate::render::engine::Engine;
use crate::render::error::UsageError;
use crate::render::progress::Progress;
use crate::render::sampling::LightSampler;
use crate::render::scene::{ParseOptions, SceneFile, load_scene};
use crate::render::settings::{LightModel, RenderSettings};
use crate::shard::{Host, Identity, Part, Shard, Work};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};

/// What `raywave variance` is asked to do (its flags, as plain values).
#[derive(Clone, Debug)]
pub struct VarianceOptions {
    /// Scene files; none for the built-in lab Cornell box with mirror spheres (`None` in the
    /// list stands for it too).
    pub scenes: Vec<Option<PathBuf>>,
    /// Light-sample budgets N.
    pub budgets: Vec<u32>,
    /// Samplers to compare.
    pub samplers: Vec<LightSampler>,
    /// Seeds (independent renders) per sampler and budget.
    pub seeds: u32,
    /// Image sizes, width and height: each scene is studied at each.
    pub sizes: Vec<[u32; 2]>,
    /// Mirror bounces.
    pub bounces: u32,
    /// Stratified points per light in each half of the converged reference.
    pub reference_samples: u32,
    /// Points per light per hit for the penumbra mask.
    pub mask_samples: u32,
    /// The budget whose per-pixel error maps are drawn (the nearest of `budgets` if it is not
    /// one, see [`VarianceOptions::heatmap_budget`]).
    pub heatmap_n: u32,
    /// Directory for the tables, plots and heat maps.
    pub out: PathBuf,
    /// Directory caching converged references.
    pub cache: PathBuf,
    /// Always render the converged reference, ignoring and not writing the cache.
    pub no_cache: bool,
    /// Bound on the cache's total size, in MiB: the least recently used entries go first.
    pub cache_limit_mib: u64,
    /// How a light's colour reaches a point.
    pub light_model: LightModel,
    /// The engine that renders the images.
    pub engine: Engine,
}

impl Default for VarianceOptions {
    /// The command's defaults: the built-in scene at 128×128, N = 1, 4, 16, 64, 256, every
    /// sampler, 8 seeds.
    fn default() -> Self {
        VarianceOptions {
            scenes: Vec::new(),
            budgets: vec![1, 4, 16, 64, 256],
            samplers: LightSampler::ALL.to_vec(),
            seeds: 8,
            sizes: vec![[128, 128]],
            bounces: 5,
            reference_samples: 4096,
            mask_samples: 1024,
            heatmap_n: 16,
            out: PathBuf::from("variance-report"),
            cache: PathBuf::from(".raywave-cache"),
            no_cache: false,
            cache_limit_mib: super::study::cache::DEFAULT_LIMIT_MIB,
            light_model: LightModel::Lab,
            engine: Engine::Wavefront,
        }
    }
}

impl VarianceOptions {
    /// Checks the flags against each other; errors name the flag.
    pub fn validate(&self) -> Result<()> {
        // Every seed's image of every sampler at one N is kept until its statistics are taken
        // (the samplers are interleaved), and one 8-bit render per sampler and N for the
        // contact sheet.
        if self.sizes.is_empty() {
            bail!(UsageError("no image size: expected at least one".into()));
        }
        for &[w, h] in &self.sizes {
            let pixels = w as u64 * h as u64;
            let samplers = self.samplers.len().max(1) as u64;
            let bytes =
                pixels * samplers * (self.seeds as u64 * 12 + self.budgets.len() as u64 * 3);
            if bytes > MAX_STUDY_BYTES {
                bail!(UsageError(format!(
                    "--seeds {} of {} samplers at --size {w} {h} would hold {:.1} GiB of images at once: expected at most {} GiB; use fewer seeds or samplers, or a smaller size",
                    self.seeds,
                    samplers,
                    bytes as f64 / (1u64 << 30) as f64,
                    MAX_STUDY_BYTES >> 30
                )));
            }
        }
        if self.out.exists() && !self.out.is_dir() {
            bail!(
                "--out {}: expected a directory, found a file",
                self.out.display()
            );
        }
        if self.budgets.is_empty() {
            bail!(UsageError(
                "--budgets is empty: expected at least one budget N".into()
            ));
        }
        if self.samplers.is_empty() {
            let names: Vec<&str> = LightSampler::ALL.iter().map(|s| s.name()).collect();
            bail!(UsageError(format!(
                "--samplers is empty: expected at least one of {}",
                names.join(", ")
            )));
        }
        // Every sampler takes every budget, or the study stops before it starts.
        let [width, height] = self.sizes[0];
        let config = StudyConfig::standard(RenderSettings {
            width,
            height,
            ..RenderSettings::default()
        });
        for &sampler in &self.samplers {
            for &n in &self.budgets {
                config.run_settings(sampler, n, 0).check_sampler().map_err(|e| {
                    UsageError(format!(
                        "{e}; the study's --budgets include {n}: leave {} out of --samplers, or that budget out",
                        sampler.name()
                    ))
                })?;
            }
        }
        Ok(())
    }

    /// The budget whose heat maps are drawn: `heatmap_n` if it is one of the budgets, else the
    /// budget nearest to it on a log scale (budgets grow by factors), the smaller on a tie.
    pub fn heatmap_budget(&self) -> u32 {
        nearest_budget(&self.budgets, self.heatmap_n).unwrap_or(self.heatmap_n)
    }
}

/// The budget of `budgets` nearest to `n` on a log scale (|log b − log n| smallest), the
/// smaller of two at the same distance; None for no budgets.
pub fn nearest_budget(budgets: &[u32], n: u32) -> Option<u32> {
    let distance = |b: u32| ((b.max(1) as f64).ln() - (n.max(1) as f64).ln()).abs();
    budgets
        .iter()
        .copied()
        .min_by(|&a, &b| distance(a).total_cmp(&distance(b)).then(a.cmp(&b)))
}

/// The largest total size of the K images a study holds at once.
const MAX_STUDY_BYTES: u64 = 4 << 30;

/// The cases of the study `options` describe: each scene at each size, in that order. Scene
/// warnings go to `notice`.
pub fn load_cases(options: &VarianceOptions, notice: &dyn Fn(&str)) -> Result<Vec<Case>> {
    let scenes = if options.scenes.is_empty() {
        vec![None]
    } else {
        options.scenes.clone()
    };
    let (mut stems, mut loaded) = (Vec::new(), Vec::new());
    for path in &scenes {
        let SceneFile { scene, bytes } = load_scene(path.as_deref(), &ParseOptions::default())?;
        for w in &scene.warnings {
            notice(&w.to_string());
        }
        if scene.lights.is_empty() {
            bail!(
                "{}: expected a scene with at least one area light (a face whose material has a non-zero `emitted`), found none: there is no light sampling to study",
                scene.source
            );
        }
        let stem = path.as_ref().and_then(|p| p.file_stem());
        stems.push(stem.map_or("builtin".to_string(), |s| s.to_string_lossy().into_owned()));
        loaded.push((scene, bytes));
    }
    let mut names = case_names(&stems, &options.sizes).into_iter();
    let samplers = super::unique(options.samplers.iter().copied());
    let budgets = super::unique(options.budgets.iter().copied());
    let mut cases = Vec::new();
    for (scene, bytes) in loaded {
        for &[width, height] in &options.sizes {
            let base = RenderSettings {
                width,
                height,
                bounces: options.bounces,
                light_model: options.light_model,
                background: scene
                    .background
                    .map_or(RenderSettings::default().background, |c| c.to_array()),
                ..RenderSettings::default()
            };
            let config = StudyConfig {
                budgets: budgets.clone(),
                samplers: samplers.clone(),
                seeds: options.seeds,
                reference_samples: options.reference_samples,
                mask_samples: options.mask_samples,
                heatmap_n: options.heatmap_budget(),
                ..StudyConfig::standard(base)
            };
            cases.push(Case {
                name: names.next().unwrap_or_default(),
                scene: scene.clone(),
                bytes: bytes.clone(),
                config,
            });
        }
    }
    Ok(cases)
}

/// The cache `options` ask for, if its directory can be made (else a warning, and none).
fn open_cache(options: &VarianceOptions, notice: &dyn Fn(&str)) -> Option<Cache> {
    let cache = (!options.no_cache).then(|| Cache::new(&options.cache, options.cache_limit_mib))?;
    match std::fs::create_dir_all(&cache.dir) {
        Ok(()) => Some(cache),
        Err(e) => {
            notice(&format!(
                "warning: cannot use the cache directory {} ({e}): the converged reference will not be cached",
                cache.dir.display()
            ));
            None
        }
    }
}

/// Runs the jobs `selected` (numbers in `identity.jobs()`) of `cases`, each case's setup first;
/// returns per case touched its number, facts and results.
fn run_selected(
    cases: &[Case],
    identity: &Identity<Study>,
    selected: &[usize],
    cache: Option<&Cache>,
    render: &RenderFn,
    progress: &Progress,
) -> Result<Vec<(usize, CaseFacts, Vec<JobResult>)>> {
    let all = identity.work.jobs();
    let costs = identity.work.costs();
    let total: f64 = selected.iter().map(|&j| costs[j]).sum();
    let rays = progress.steps(total as u64, "rays");
    let host = crate::output::machine::hostname();
    let mut out = Vec::new();
    for (c, case) in cases.iter().enumerate() {
        let jobs: Vec<Job> = selected
            .iter()
            .map(|&j| all[j])
            .filter(|j| j.case == c)
            .collect();
        if jobs.is_empty() {
            continue;
        }
        let (scene, config) = (&case.scene, &case.config);
        let label =
            |done: f64, what: &str| rays.advance(done as u64, &format!("{}: {what}", case.name));
        label(0.0, "converged reference and regions");
        let setup = Setup::new(scene, &case.bytes, config, render, cache, progress.notice)?;
        let results = jobs::run_jobs(scene, config, &setup, &jobs, render, &host, &label);
        out.push((c, setup.facts(), results));
    }
    Ok(out)
}

/// A finished study: its cases' results, and the files written.
pub struct Outcome {
    /// One per case, in order.
    pub results: Vec<super::StudyResult>,
    /// The summary across cases (None for one case).
    pub summary: Option<Summary>,
    /// The files written into `--out`, in order.
    pub written: Vec<PathBuf>,
}

impl Outcome {
    /// What a finished study prints: the one case's table, or the summary across cases.
    pub fn table(&self) -> String {
        match (&self.summary, self.results.as_slice()) {
            (Some(summary), results) => summary.table(results),
            (None, [one]) => one.table(),
            (None, _) => String::new(),
        }
    }
}

/// Runs the whole study of `cases` in this process, on the current rayon pool, and writes its
/// report into `options.out`. Reports through `progress`; prints nothing.
pub fn study(
    options: &VarianceOptions,
    cases: &[Case],
    render: &RenderFn,
    progress: &Progress,
) -> Result<Outcome> {
    options.validate()?;
    create_out(&options.out)?;
    let cache = open_cache(options, progress.notice);
    let engine = options.engine.name();
    let identity = identity(cases, engine);
    let all: Vec<usize> = (0..identity.work.jobs().len()).collect();
    let ran = run_selected(cases, &identity, &all, cache.as_ref(), render, progress)?;
    let threads = rayon::current_num_threads();
    let results = ran
        .into_iter()
        .map(|(c, facts, results)| {
            let (config, source) = (&cases[c].config, &cases[c].scene.source);
            jobs::assemble(config, source, engine, threads, facts, results)
        })
        .collect::<Vec<_>>();
    let names: Vec<String> = cases.iter().map(|c| c.name.clone()).collect();
    write_report(&names, results, &options.out, progress.notice)
}

/// Makes the output directory, failing now rather than after minutes of rendering.
pub(crate) fn create_out(out: &Path) -> Result<()> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create the output directory {}", out.display()))
}

/// Writes the report of `results` (named `names`) into `out`: one case's files there, or each
/// case's in `out/NAME/` and the summary across them; then warns where a reference's own error
/// comes near the errors measured.
pub(crate) fn write_report(
    names: &[String],
    results: Vec<super::StudyResult>,
    out: &Path,
    notice: &(dyn Fn(&str) + Sync),
) -> Result<Outcome> {
    let mut written = Vec::new();
    let summary = if let [one] = results.as_slice() {
        written.extend(one.write(out)?);
        None
    } else {
        for (name, result) in names.iter().zip(&results) {
            written.extend(result.write(&out.join(name))?);
        }
        let summary = super::report::summary::summarize(names, &results);
        written.extend(summary.write(&results, out)?);
        Some(summary)
    };
    for (name, result) in names.iter().zip(&results) {
        for region in [Region::Penumbra, Region::Lit] {
            let margin = result.reference_margin(region);
            if result.facts.region_pixels[region as usize] > 0 && margin < 10.0 {
                let case = if results.len() > 1 {
                    format!("{name}: ")
                } else {
                    String::new()
                };
                notice(&format!(
                    "warning: {case}the converged reference's own error is only {margin:.1}× below the smallest MSE measured on the {} region; raise --reference-samples",
                    region.name()
                ));
            }
        }
    }
    Ok(Outcome {
        results,
        summary,
        written,
    })
}

/// Runs shard `shard` of the study of `cases` and writes its part into `options.out`; returns
/// the part's path and how many jobs it ran.
pub fn run_shard(
    options: &VarianceOptions,
    cases: &[Case],
    shard: Shard,
    render: &RenderFn,
    progress: &Progress,
) -> Result<(PathBuf, usize)> {
    options.validate()?;
    create_out(&options.out)?;
    let cache = open_cache(options, progress.notice);
    let identity = identity(cases, options.engine.name());
    let items = shard.items(&identity.work.costs());
    let host = Host::start(rayon::current_num_threads());
    let ran = run_selected(cases, &identity, &items, cache.as_ref(), render, progress)?;
    let mut part = Part {
        identity,
        shard,
        items,
        host,
        extra: Vec::new(),
        results: Vec::new(),
    };
    for (c, facts, results) in ran {
        part.extra.push((c, cases[c].scene.source.clone(), facts));
        part.results
            .extend(results.into_iter().map(JobResult::convert));
    }
    part.host.finish();
    let path = crate::shard::write_part(&options.out, &part)?;
    Ok((path, part.items.len()))
}

/// Fills the cache with the converged reference of every case (`raywave variance prepare`);
/// returns per case its name and whether the reference was already there.
pub fn prepare(
    options: &VarianceOptions,
    cases: &[Case],
    render: &RenderFn,
    progress: &Progress,
) -> Result<Vec<(String, bool)>> {
    options.validate()?;
    if options.no_cache {
        bail!(UsageError(
            "`raywave variance prepare` fills the cache: --no-cache leaves it nothing to do".into()
        ));
    }
    let Some(cache) = open_cache(options, progress.notice) else {
        bail!(
            "cannot use the cache directory {}: nothing prepared",
            options.cache.display()
        );
    };
    let mut out = Vec::new();
    for (i, case) in cases.iter().enumerate() {
        (progress.report)(i as u64, cases.len() as u64, &case.name);
        let reference = super::converged_reference(
            &case.scene,
            &case.bytes,
            &case.config,
            render,
            Some(&cache),
            progress.notice,
        )?;
        out.push((case.name.clone(), reference.cached));
    }
    Ok(out)
}
