//! `raywave variance` flags, turned into `raywave::variance::command::VarianceOptions`; `raywave
//! variance prepare` (fill the reference cache) and `raywave variance merge` (join shards).

use super::image::ThreadsArg;
use super::values::{EngineArg, LightModelArg, SamplerArg};
use anyhow::Result;
use clap::{Args, Subcommand, ValueEnum};
use raywave::output::OutputPlan;
use raywave::output::terminal::{print, with_bar};
use raywave::render::engine::{clamped_warning, thread_pool};
use raywave::render::progress::Progress;
use raywave::render::scene::Scene;
use raywave::render::settings::RenderSettings;
use raywave::render::wavefront::DEFAULT_BATCH_SIZE;
use raywave::shard::Shard;
use raywave::variance::command::{VarianceOptions, load_cases, prepare, run_shard, study};
use raywave::variance::study::plan::{Case, Study, identity};
use std::path::{Path, PathBuf};

/// Flags of `raywave variance`. A scene file literally named `prepare` or `merge` is given as
/// `./prepare` or `./merge` (the bare words are the subcommands).
#[derive(Args, Debug, Clone)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct VarianceArgs {
    /// Fill the cache ahead of a sharded study, or merge the shards' parts.
    #[command(subcommand)]
    pub action: Option<VarianceAction>,
    /// What to study.
    #[command(flatten)]
    pub study: StudyArgs,
    /// Directory for the report: table.txt, results.csv, seeds.csv, perceived.csv,
    /// spectra.csv, results.json, mse.png, contact_sheet.png, the heat maps and the spectra
    /// (with several cases, one directory per case and summary.txt/.csv/.json); with --shard,
    /// the directory of the shard's part, variance-shard-I-of-N.part.
    #[arg(long, default_value = "variance-report")]
    pub out: PathBuf,
    /// Run only shard I of N (0-based: 0/4 to 3/4) and write its part into --out, for a batch
    /// system to run every shard ($SLURM_ARRAY_TASK_ID/4, $JOB_COMPLETION_INDEX/4, GNU
    /// parallel's {}); `raywave variance merge` joins the parts. The jobs are split by their
    /// estimated rays.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Remove every converged reference from the --cache directory (other files are left
    /// alone) and exit, without running a study.
    #[arg(long, conflicts_with_all = ["scenes", "study", "shard"])]
    pub clean_cache: bool,
    #[command(flatten)]
    pub workers: ThreadsArg,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

/// The subcommands of `raywave variance`.
#[derive(Subcommand, Debug, Clone)]
pub(crate) enum VarianceAction {
    /// Render every case's converged reference into --cache, so that the shards of a study
    /// find it there instead of racing to render it.
    Prepare(PrepareArgs),
    /// Join the parts of every shard of a study into its report, the same as one process
    /// would have written; refuses parts that are missing, repeated, cut short, or of another
    /// study or raywave build.
    Merge(MergeArgs),
}

/// Flags of `raywave variance prepare`.
#[derive(Args, Debug, Clone)]
pub(crate) struct PrepareArgs {
    /// What to study.
    #[command(flatten)]
    pub study: StudyArgs,
    #[command(flatten)]
    pub workers: ThreadsArg,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Flags of `raywave variance merge`.
#[derive(Args, Debug, Clone)]
pub struct MergeArgs {
    /// The shards' part files, or directories holding them (their variance-shard-*.part files).
    #[arg(required = true, value_name = "PARTS")]
    pub parts: Vec<PathBuf>,
    /// Directory for the report (not one of the inputs).
    #[arg(long, default_value = "variance-report")]
    pub out: PathBuf,
}

/// What a study measures and where: the scenes or a study file, and the measuring flags.
#[derive(Args, Debug, Clone)]
pub(crate) struct StudyArgs {
    /// Scene files; without one, the built-in lab Cornell box with mirror spheres.
    pub scenes: Vec<PathBuf>,
    /// A study file (TOML: scenes, samplers, budgets, seeds, sizes, ...; docs/SAMPLING.md and
    /// docs/schema/study.schema.json), instead of the scenes and measuring flags.
    #[arg(long, value_name = "FILE.toml", conflicts_with_all = ["scenes", "budgets", "samplers",
          "seeds", "size", "bounces", "reference_samples", "mask_samples", "heatmap_n",
          "light_model", "engine"])]
    pub study: Option<PathBuf>,
    /// Light-sample budgets N: comma- or space-separated (`1,4,16` or `1 4 16`; with spaces,
    /// give SCENE before this flag).
    #[arg(long, num_args = 1.., value_delimiter = ',', default_values_t = [1u32, 4, 16, 64, 256], value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub budgets: Vec<u32>,
    /// Samplers to compare: comma- or space-separated (`random,sobol` or `random sobol`; with
    /// spaces, give SCENE before this flag).
    #[arg(long, value_enum, num_args = 1.., value_delimiter = ',', default_values_t = SamplerArg::value_variants())]
    pub samplers: Vec<SamplerArg>,
    /// Seeds (independent renders) per sampler and budget; at least 2, for the variance.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(2..=1024))]
    pub seeds: u32,
    /// Image size.
    #[arg(long, num_args = 2, action = clap::ArgAction::Set, value_names = ["W", "H"], default_values_t = [128u32, 128], value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub size: Vec<u32>,
    /// Mirror bounces.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(0..=64))]
    pub bounces: u32,
    /// Stratified points per light in each half of the converged reference.
    #[arg(long, default_value_t = 4096, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub reference_samples: u32,
    /// Points per light per hit for the penumbra mask.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub mask_samples: u32,
    /// The budget whose per-pixel error maps are drawn; a value that is not one of --budgets
    /// picks the nearest of them on a log scale (with a note on standard error).
    #[arg(long, default_value_t = 16)]
    pub heatmap_n: u32,
    /// Directory caching converged references (keyed by the scene bytes parsed, the settings
    /// and the executable; every entry is checked when read and rendered again if it fails).
    /// Shards on several machines share it on a shared filesystem: an entry is rendered once,
    /// under a lock, and read by the others.
    #[arg(long, default_value = ".raywave-cache")]
    pub cache: PathBuf,
    /// Always render the converged reference, ignoring and not writing the cache.
    #[arg(long, conflicts_with_all = ["cache", "cache_limit", "clean_cache"])]
    pub no_cache: bool,
    /// Bound on the cache's total size in MiB; the least recently used entries are removed
    /// above it.
    #[arg(long, value_name = "MIB",
          default_value_t = raywave::variance::study::cache::DEFAULT_LIMIT_MIB,
          value_parser = clap::value_parser!(u64).range(1..=1 << 30))]
    pub cache_limit: u64,
    /// How a light's colour reaches a point: lab (no fall-off) or rpi (divided by π·d², as
    /// RPI's framework does).
    #[arg(long, value_enum, default_value = "lab")]
    pub light_model: LightModelArg,
    /// The engine that renders the images (both draw the same samples).
    #[arg(long, value_enum, default_value = "wavefront")]
    pub engine: EngineArg,
}

impl StudyArgs {
    /// The flags (or the study file they name) as the library's options, writing into `out`.
    pub fn options(&self, out: &Path) -> Result<VarianceOptions> {
        let mut options = VarianceOptions {
            scenes: self.scenes.iter().cloned().map(Some).collect(),
            budgets: self.budgets.clone(),
            samplers: self.samplers.iter().map(|&s| s.into()).collect(),
            seeds: self.seeds,
            sizes: vec![[self.size[0], self.size[1]]],
            bounces: self.bounces,
            reference_samples: self.reference_samples,
            mask_samples: self.mask_samples,
            heatmap_n: self.heatmap_n,
            out: out.to_path_buf(),
            cache: self.cache.clone(),
            no_cache: self.no_cache,
            cache_limit_mib: self.cache_limit,
            light_model: self.light_model.into(),
            engine: self.engine.into(),
        };
        if let Some(file) = &self.study {
            raywave::variance::study::study_file::read(file, &mut options)?;
        }
        Ok(options)
    }
}

/// Loads the cases, printing the scenes' warnings and the heat-map note.
fn cases(options: &VarianceOptions) -> Result<Vec<Case>> {
    options.validate()?;
    let cases = load_cases(options, &|w| eprintln!("{w}"))?;
    let heatmap_n = options.heatmap_budget();
    if heatmap_n != options.heatmap_n {
        eprintln!(
            "note: --heatmap-n {} is not one of --budgets; drawing the heat maps at the nearest budget, N = {heatmap_n}",
            options.heatmap_n
        );
    }
    Ok(cases)
}

/// Runs `work` with a progress bar over estimated rays (`prefix` before it; none if `quiet`)
/// and the renderer of `options`, whose clamp warnings are printed above the bar.
fn with_progress<T>(
    options: &VarianceOptions,
    quiet: bool,
    prefix: &str,
    work: impl FnOnce(&raywave::variance::RenderFn, &Progress) -> Result<T>,
) -> Result<T> {
    let template = format!(
        "{{spinner}} {prefix} [{{bar:30}}] ~{{human_pos}}/{{human_len}} rays, {{msg}} ({{elapsed}}, eta {{eta}})"
    );
    with_bar(&template, quiet, |progress| {
        let render = |scene: &Scene, settings: &RenderSettings| {
            let (film, stats) =
                options
                    .engine
                    .render(scene, settings, DEFAULT_BATCH_SIZE, &Progress::SILENT);
            if let Some(w) = clamped_warning(&stats) {
                (progress.notice)(&w);
            }
            (film, stats.counts)
        };
        work(&render, progress)
    })
}

/// Checks `plan`, and that none of its outputs is a texture one of the cases' scenes read.
fn check(plan: &OutputPlan, cases: &[Case]) -> Result<()> {
    plan.check()?;
    cases
        .iter()
        .try_for_each(|case| plan.check_scene_files(&format!("case {}", case.name), &case.scene))
}

fn joined(paths: &[PathBuf]) -> String {
    paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Runs the study (or one shard of it, or a subcommand) on `--threads` worker threads.
pub fn run(args: &VarianceArgs) -> Result<()> {
    match &args.action {
        Some(VarianceAction::Prepare(p)) => return run_prepare(p),
        Some(VarianceAction::Merge(m)) => return run_merge(m),
        None => {}
    }
    let options = args.study.options(&args.out)?;
    if args.clean_cache {
        let (files, bytes) = raywave::variance::study::cache::clean(&options.cache)?;
        return print(&format!(
            "removed {files} cache entr{} ({:.1} MiB) from {}\n",
            if files == 1 { "y" } else { "ies" },
            bytes as f64 / (1u64 << 20) as f64,
            options.cache.display()
        ));
    }
    let cases = cases(&options)?;
    let pool = thread_pool(args.workers.threads)?;
    let plan = OutputPlan::new().input_if("--study", args.study.study.as_deref());
    let plan = (options.scenes.iter().flatten()).fold(plan, |plan, s| plan.input("SCENE", s));
    let work = identity(&cases, options.engine.name()).work;
    if let Some(shard) = args.shard {
        let part = options.out.join(raywave::shard::part_name::<Study>(shard));
        let plan = plan.output_in_new_dir("--out", &part);
        check(&plan, &cases)?;
        let jobs = work.assignment(shard.count)[shard.index].len();
        let prefix = format!("variance shard {shard}, {jobs} jobs");
        let (path, jobs) = with_progress(&options, args.quiet, &prefix, |render, progress| {
            pool.install(|| run_shard(&options, &cases, shard, render, progress))
        })?;
        return print(&format!(
            "shard {shard}: ran {jobs} job{} of the study\nwrote   {}\n",
            if jobs == 1 { "" } else { "s" },
            path.display()
        ));
    }
    let plan = (report_files(&options, &cases).into_iter()).fold(plan, |plan, name| {
        plan.output_in_new_dir("--out", &options.out.join(name))
    });
    check(&plan, &cases)?;
    let prefix = format!("variance, {} jobs", work.jobs().len());
    let outcome = with_progress(&options, args.quiet, &prefix, |render, progress| {
        pool.install(|| study(&options, &cases, render, progress))
    })?;
    let cached = outcome
        .results
        .iter()
        .filter(|r| r.facts.reference_cached)
        .count();
    print(&format!(
        "{}\nconverged reference{}: {}\nwrote   {}\n",
        outcome.table(),
        if cases.len() == 1 { "" } else { "s" },
        match (cached, outcome.results.len()) {
            (0, _) => "rendered".to_string(),
            (c, n) if c == n => "from the cache".to_string(),
            (c, n) => format!("{c} of {n} from the cache"),
        },
        joined(&outcome.written)
    ))
}

/// The files the study's report writes into --out.
fn report_files(options: &VarianceOptions, cases: &[Case]) -> Vec<String> {
    let per_case = raywave::variance::report::tables::file_names(
        &options.samplers,
        &options.budgets,
        options.heatmap_budget(),
    );
    if cases.len() == 1 {
        per_case
    } else {
        let names: Vec<String> = cases.iter().map(|c| c.name.clone()).collect();
        raywave::variance::report::summary::file_names(&names, &per_case)
    }
}

fn run_prepare(args: &PrepareArgs) -> Result<()> {
    let options = args.study.options(Path::new("variance-report"))?;
    let cases = cases(&options)?;
    let pool = thread_pool(args.workers.threads)?;
    let prepared = with_progress(&options, args.quiet, "prepare", |render, progress| {
        pool.install(|| prepare(&options, &cases, render, progress))
    })?;
    let mut text = String::new();
    for (name, cached) in prepared {
        text.push_str(&format!(
            "{name}: converged reference {}\n",
            if cached {
                "already in the cache"
            } else {
                "rendered and cached"
            }
        ));
    }
    text.push_str(&format!("cache   {}\n", options.cache.display()));
    print(&text)
}

fn run_merge(args: &MergeArgs) -> Result<()> {
    let started = std::time::Instant::now();
    (args.parts.iter())
        .fold(OutputPlan::new(), |plan, part| plan.input("PARTS", part))
        .check()?;
    let merged = raywave::variance::merge::merge(&args.parts, &args.out, &|w| eprintln!("{w}"))?;
    print(&format!(
        "{}\n{}merge   {:.2} s\nwrote   {}\n",
        merged.outcome.table(),
        merged.describe(),
        started.elapsed().as_secs_f64(),
        joined(&merged.outcome.written)
    ))
}
