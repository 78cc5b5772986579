//! The `raywave` command. `main` owns the exit code: 0 on success (for `raywave bench --against`
//! also "not slower by more than the threshold", and a fixed-rounds run left undecided), 2 for a
//! usage error (clap) and for a CPU without an x86 feature the build uses
//! (`raywave::output::cpu`), 3 when `raywave bench --compare` or `--against` finds a regression or
//! `raywave diff --fail-above` a figure past its threshold, 4 when `raywave bench --against
//! --until-decided` ends undecided at its budget (neither a regression nor shown not to be one,
//! in either `--verdict` form), 1 for anything else, printed once with its cause chain; 130
//! after SIGINT and 143 after SIGTERM (`output::write`; `raywave view` after answering the
//! requests in hand). The command line itself is in `cli/`, one file per command.

mod cli;

use cli::Command;
use raywave::render::error::UsageError;
use std::process::ExitCode;

fn main() -> ExitCode {
    // Exit 2, naming them, when this CPU lacks instructions the build uses: before any code
    // that might use them.
    raywave::output::cpu::exit_unless_supported();
    raywave::frame::phases::start();
    let normalized = match cli::foreign::normalize_args(std::env::args_os()) {
        Ok(n) => n,
        Err(e) => {
            eprintln!("error: {e}\n\nFor more information, try '--help'.");
            return ExitCode::from(2);
        }
    };
    let (cli, matches) = match cli::parse(&normalized.args) {
        Ok(parsed) => parsed,
        // --help and --version.
        Err(e) if !e.use_stderr() => e.exit(),
        // Usage errors name the flags as typed (`-num_bounces`, not `--bounces`).
        Err(e) => {
            eprint!("{}", normalized.respell(&e.to_string()));
            return ExitCode::from(e.exit_code().clamp(0, 255) as u8);
        }
    };
    // SIGINT/SIGTERM: remove unfinished temporary files, exit 130/143. `raywave view` writes no
    // files and handles them itself (module doc).
    if !matches!(cli.command, Command::View(_))
        && let Err(e) = raywave::output::install_signal_cleanup()
    {
        eprintln!("error: {e:#}");
        return ExitCode::from(1);
    }
    // Outputs reach their files only when the command has succeeded: a run that fails part
    // of the way changes none of them (output::write).
    raywave::output::hold_outputs();
    // Lab and RPI flags accepted without effect: one line each, like the scene's warnings.
    for note in &normalized.notes {
        eprintln!("note: {note}");
    }
    // Flags the other flags make meaningless: accepted, with one line each.
    for warning in cli::combos::meaningless(&cli.command, &|flag| normalized.typed(flag)) {
        eprintln!("warning: {warning}");
    }
    // Each command's own exit code when it succeeds (module doc).
    let result: anyhow::Result<u8> = match cli.command {
        Command::Render(args) => cli::render::run(&args).map(|()| 0),
        Command::Info => cli::info::run().map(|()| 0),
        Command::Meshgen(args) => cli::meshgen::run(&args).map(|()| 0),
        Command::Variance(args) => cli::variance::run(&args).map(|()| 0),
        Command::View(args) => cli::view::run(&args),
        Command::TracePixel(args) => cli::trace_pixel::run(&args).map(|()| 0),
        // raywave::bench::EXIT_REGRESSION, EXIT_UNDECIDED.
        Command::Bench(args) => cli::bench::run(&args, matches.subcommand_matches("bench")),
        // raywave::diff::EXIT_FAILED.
        Command::Diff(args) => cli::diff::run(&args),
    };
    // A run that failed changes no output; one that succeeded puts them all in place.
    let result = result
        .inspect_err(|_| raywave::output::discard_outputs())
        .and_then(|code| raywave::output::commit_outputs().map(|()| code));
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) if e.downcast_ref::<UsageError>().is_some() => {
            eprintln!("error: {e:#}\n\nFor more information, try '--help'.");
            ExitCode::from(2)
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}
