//! The lab's and RPI's spellings (`-size 200 200 -input f.obj -soft_shadow ...`) translated
//! into raywave's flags from one table, `FOREIGN_FLAGS`, so that their run lines work verbatim
//! and clap validates every spelling the same way.

use super::values::DefaultsArg;
use clap::CommandFactory;
use raywave::render::error::UsageError;
use raywave::render::settings::options::Defaults;
use std::ffi::OsString;

/// What one value of a lab or RPI flag must look like.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Value {
    /// A whole number, 0 or more.
    Count,
    /// A finite number.
    Number,
    /// Any text (a file name).
    Text,
}

/// What a lab or RPI flag does in raywave.
#[derive(Clone, Copy, Debug)]
enum Meaning {
    /// This raywave flag, followed by the values as given.
    Flag(&'static str),
    /// These raywave arguments (the flag takes no values).
    Tokens(&'static [&'static str]),
    /// `-num_shadow_samples N`: `--shadow-samples N`, except that 0, both programs' default,
    /// is no count: the lab then shades hard shadows (or soft ones with raywave's count), RPI
    /// casts no shadow rays at all (`--shadows off`).
    ShadowSamples,
    /// Accepted and checked, then ignored with a note on stderr giving this reason.
    NoEffect(&'static str),
}

/// Which dashes a flag is spelled with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Dashes {
    /// `-name` only: the lab's ArgParser, or RPI's older single-dash one.
    One,
    /// `-name` and RPI 2023's `--name`.
    Both,
}

/// One flag of the lab's or RPI's ArgParser: its name without the dashes, the dashes it is
/// spelled with, the values that follow it, and what it does in raywave.
type ForeignFlag = (&'static str, Dashes, &'static [Value], Meaning);

const RADIOSITY: &str = "raywave has no radiosity solver";
const PHOTONS: &str = "raywave has no photon mapping; indirect light stays the ambient term";
const SPHERES: &str = "raywave intersects spheres exactly; RPI cuts them into patches only for radiosity and its OpenGL view";
const GLOSSY: &str =
    "raywave traces no glossy reflection rays; glossiness only widens the highlight";

use Dashes::{Both, One};
use Meaning::{Flag, NoEffect, ShadowSamples, Tokens};
use Value::{Count, Number, Text};

/// Every flag of the lab's ArgParser and RPI's (single-dash, and the 2023 double-dash forms),
/// with raywave's meaning: one place to read and extend. Sources: the lab's `argparser.h`,
/// RPI's (adding `-i`, the ring, antialiasing and ambient flags and photon mapping's) and RPI's
/// 2023 `argparser.cpp` (the same with two dashes, without `-i`). `-output` is raywave's own
/// single-dash spelling of `-o`, kept for lab-style lines.
#[rustfmt::skip]
const FOREIGN_FLAGS: &[ForeignFlag] = &[
    ("input",                       Both, &[Text],                   Flag("--input")),
    ("i",                           One,  &[Text],                   Flag("--input")),
    ("output",                      One,  &[Text],                   Flag("--output")),
    ("size",                        Both, &[Count, Count],           Flag("--size")),
    ("num_bounces",                 Both, &[Count],                  Flag("--bounces")),
    ("num_shadow_samples",          Both, &[Count],                  ShadowSamples),
    ("soft_shadow",                 One,  &[],                       Tokens(&["--shadows", "soft"])),
    ("background_color",            One,  &[Number, Number, Number], Flag("--background")),
    ("num_antialias_samples",       Both, &[Count],                  Flag("--aa")),
    ("ambient_light",               Both, &[Number, Number, Number], Flag("--ambient")),
    ("cylinder_ring_rasterization", Both, &[Count],                  Flag("--ring-segments")),
    ("sphere_rasterization",        Both, &[Count, Count],           NoEffect(SPHERES)),
    ("num_glossy_samples",          Both, &[Count],                  NoEffect(GLOSSY)),
    ("num_form_factor_samples",     Both, &[Count],                  NoEffect(RADIOSITY)),
    ("num_photons_to_shoot",        Both, &[Count],                  NoEffect(PHOTONS)),
    ("num_photons_to_collect",      Both, &[Count],                  NoEffect(PHOTONS)),
    ("gather_indirect",             Both, &[],                       NoEffect(PHOTONS)),
];

/// Spellings in the table that are also raywave's own: they do not choose whose defaults apply.
const RAYWAVE_SPELLINGS: &[&str] = &["-output", "--input", "--size"];

/// raywave flags a lab or RPI flag can stand for, with the setting they name in messages.
const TARGETS: &[(&str, &str)] = &[
    ("--input", "the scene"),
    ("--output", "the output file"),
    ("-o", "the output file"),
    ("--size", "the size"),
    ("--bounces", "the bounces"),
    ("--shadows", "the shadow mode"),
    ("--shadow-samples", "the shadow samples"),
    ("--background", "the background"),
    ("--aa", "the antialiasing samples"),
    ("--ambient", "the ambient light"),
    ("--ring-segments", "the ring segments"),
];

/// The subcommands that take the image flags, and so the lab's and RPI's spellings.
const IMAGE_COMMANDS: &[&str] = &["render", "bench"];

/// The words besides clap's subcommands that clap reads in a subcommand's place.
const NOT_RENDER: &[&str] = &["help", "-h", "--help", "-V", "--version"];

/// argv rewritten for clap, and the notes to print on stderr.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Normalized {
    /// The arguments clap reads.
    pub args: Vec<OsString>,
    /// One line each for flags accepted without effect (printed with a `note:` prefix).
    pub notes: Vec<String>,
    /// (raywave flag, the lab's or RPI's spelling the user typed for it), so that messages
    /// name flags as typed.
    pub spellings: Vec<(&'static str, String)>,
}

impl Normalized {
    /// How the user spelled raywave's `flag` (the flag itself when typed as raywave's).
    pub fn typed(&self, flag: &str) -> String {
        self.spellings
            .iter()
            .find(|(target, _)| *target == flag)
            .map_or_else(|| flag.to_string(), |(_, typed)| typed.clone())
    }

    /// A message of clap's about raywave's flags, with each flag named as the user typed it
    /// (`'--bounces <BOUNCES>'` becomes `'-num_bounces <BOUNCES>'`) and control characters
    /// from the command line escaped.
    pub fn respell(&self, message: &str) -> String {
        let mut out = message.to_string();
        for (target, typed) in &self.spellings {
            for end in [' ', '\''] {
                out = out.replace(&format!("'{target}{end}"), &format!("'{typed}{end}"));
            }
        }
        out.split('\n')
            .map(raywave::render::quote::escape)
            .collect::<Vec<_>>()
            .join("\n")
    }
}

/// The table entry for an argument, and whose spelling it is (`None`: raywave's own).
fn foreign(arg: &str) -> Option<(&'static ForeignFlag, Option<Defaults>)> {
    let (name, double) = match arg.strip_prefix("--") {
        Some(name) => (name, true),
        None => (arg.strip_prefix('-')?, false),
    };
    let flag = (FOREIGN_FLAGS.iter()).find(|f| f.0 == name && (!double || f.1 == Both))?;
    let dialect = if double { Defaults::Rpi } else { Defaults::Lab };
    Some((flag, (!RAYWAVE_SPELLINGS.contains(&arg)).then_some(dialect)))
}

/// Reads the values of `spelling` from `rest`, checking each one.
fn take_values<'a>(
    spelling: &str,
    kinds: &[Value],
    rest: &mut impl Iterator<Item = &'a OsString>,
) -> Result<Vec<String>, UsageError> {
    let what = match (kinds.first(), kinds.len()) {
        (Some(Value::Count), 1) => "a whole number".to_string(),
        (Some(Value::Count), n) => format!("{n} whole numbers"),
        (Some(Value::Number), n) => format!("{n} numbers"),
        _ => "a file name".to_string(),
    };
    kinds
        .iter()
        .map(|kind| {
            let found = match (rest.next().map(|v| v.to_string_lossy().into_owned()), kind) {
                (Some(v), Value::Count) if v.parse::<u32>().is_ok() => return Ok(v),
                (Some(v), Value::Number) if v.parse::<f32>().is_ok_and(f32::is_finite) => {
                    return Ok(v);
                }
                (Some(v), Value::Text) => return Ok(v),
                (None, _) => "the end of the command line".to_string(),
                // `1e39` is a number, just not an f32: say so, as the scene parser does.
                (Some(v), Value::Number)
                    if v.parse::<f32>().is_ok_and(|x| !x.is_finite())
                        && raywave::render::scene::beyond_range(&v) =>
                {
                    format!("`{v}`, of magnitude past the largest f32, 3.4e38")
                }
                (Some(v), _) => format!("`{v}`"),
            };
            Err(UsageError(format!(
                "{spelling}: expected {what}, found {found}"
            )))
        })
        .collect()
}

/// Rewrites argv so clap can read it. A command line without a subcommand (`raywave`,
/// `raywave scene.obj`, `raywave -size ...`) becomes `raywave render ...`. For `render` and
/// `bench`, the lab's and RPI's spellings become raywave's flags (see `FOREIGN_FLAGS`), and
/// they choose whose defaults fill the rest:
///
/// - the lab's single-dash spellings (also RPI's older single-dash ones): `--defaults lab`;
/// - RPI 2023's double-dash spellings (`--num_bounces`, ...; `--input` and `--size` are
///   raywave's too and choose nothing): `--defaults rpi`;
/// - an explicit `--defaults` wins over both;
/// - raywave's own flags mix freely with either: each still sets its setting, and the chosen
///   defaults fill only what no flag sets;
/// - the lab's and RPI 2023's spellings on one line, or one setting given twice under two
///   spellings (`-num_bounces 0 --bounces 3`), are usage errors.
pub fn normalize_args(args: impl IntoIterator<Item = OsString>) -> Result<Normalized, UsageError> {
    let mut args = args.into_iter();
    let program = args.next().unwrap_or_else(|| "raywave".into());
    let args: Vec<OsString> = args.collect();
    let first = args.first().and_then(|a| a.to_str()).unwrap_or("");
    let named = NOT_RENDER.contains(&first)
        || (super::Cli::command().get_subcommands()).any(|c| c.get_name() == first);
    let (command, rest) = if named {
        (first.to_string(), args[1..].to_vec())
    } else {
        ("render".to_string(), args)
    };
    let mut out = vec![program, OsString::from(&command)];
    if !IMAGE_COMMANDS.contains(&command.as_str()) {
        out.extend(rest);
        return Ok(Normalized {
            args: out,
            ..Default::default()
        });
    }

    // Whose defaults: an explicit --defaults, else the spellings used.
    let explicit = rest.iter().enumerate().find_map(|(i, a)| {
        let value = match a.to_str()?.strip_prefix("--defaults") {
            Some("") => rest.get(i + 1)?.to_str()?,
            Some(v) => v.strip_prefix('=')?,
            None => return None,
        };
        <DefaultsArg as clap::ValueEnum>::from_str(value, false)
            .ok()
            .map(Defaults::from)
    });
    let spelling = |dialect| {
        (rest.iter().filter_map(|a| a.to_str()))
            .find(|a| matches!(foreign(a), Some((_, Some(d))) if d == dialect))
    };
    let detected = match (spelling(Defaults::Lab), spelling(Defaults::Rpi)) {
        (Some(lab), Some(rpi)) => {
            return Err(UsageError(format!(
                "`{lab}` is the lab's spelling and `{rpi}` RPI 2023's: expected one program's flags on a command line"
            )));
        }
        (Some(_), None) => Some(Defaults::Lab),
        (None, Some(_)) => Some(Defaults::Rpi),
        (None, None) => None,
    };
    let dialect = explicit.or(detected).unwrap_or(Defaults::Raywave);
    if explicit.is_none()
        && let Some(d) = detected
    {
        out.extend(["--defaults", d.name()].map(OsString::from));
    }

    let mut notes = Vec::new();
    let mut spellings: Vec<(&'static str, String)> = Vec::new();
    // The setting each raywave flag sets, and the spelling that set it first.
    let mut set_by: Vec<(&str, String)> = Vec::new();
    let mut claim = |target: &str, spelling: &str| -> Result<(), UsageError> {
        let Some(&(target, what)) = TARGETS.iter().find(|(t, _)| *t == target) else {
            return Ok(());
        };
        let target = if target == "-o" { "--output" } else { target };
        // `bench --size W H --size W H` sweeps sizes (raywave's own spelling only).
        if command == "bench" && target == "--size" && spelling == "--size" {
            return Ok(());
        }
        if let Some((_, first)) = set_by.iter().find(|(t, _)| *t == target) {
            return Err(UsageError(format!(
                "`{first}` and `{spelling}` both set {what}: expected it once"
            )));
        }
        set_by.push((target, spelling.to_string()));
        Ok(())
    };
    let mut rest = rest.iter();
    while let Some(arg) = rest.next() {
        let Some(text) = arg.to_str() else {
            out.push(arg.clone());
            continue;
        };
        let Some((&(_, _, kinds, meaning), _)) = foreign(text) else {
            claim(text, text)?;
            // A single dash and a letter: `-x`, not `--x` nor `-1`.
            if text.len() > 2
                && text.starts_with('-')
                && text[1..].starts_with(|c: char| c.is_ascii_alphabetic())
            {
                return Err(UsageError(format!(
                    "unknown flag `{text}`: expected one of raywave's flags (--help lists them), or one of the lab's or RPI's: {}",
                    FOREIGN_FLAGS
                        .iter()
                        .map(|f| format!("-{}", f.0))
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            }
            out.push(arg.clone());
            continue;
        };
        let values = take_values(text, kinds, &mut rest)?;
        // The raywave flag it stands for, and the values that follow that flag.
        let (target, values) = match meaning {
            Meaning::Flag(target) => (target, values),
            Meaning::Tokens(args) => (args[0], args[1..].iter().map(|a| a.to_string()).collect()),
            Meaning::ShadowSamples if values[0] != "0" => ("--shadow-samples", values),
            Meaning::ShadowSamples if dialect == Defaults::Rpi => {
                ("--shadows", vec!["off".to_string()])
            }
            Meaning::ShadowSamples => continue,
            Meaning::NoEffect(why) => {
                let given = [vec![text.to_string()], values].concat().join(" ");
                notes.push(format!("{given}: accepted, no effect in raywave ({why})"));
                continue;
            }
        };
        claim(target, text)?;
        if target != text {
            spellings.push((target, text.to_string()));
        }
        out.push(target.into());
        out.extend(values.into_iter().map(OsString::from));
    }
    Ok(Normalized {
        args: out,
        notes,
        spellings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn norm(line: &str) -> Result<Normalized, UsageError> {
        normalize_args(
            std::iter::once("raywave".into()).chain(line.split_whitespace().map(OsString::from)),
        )
    }

    fn args(line: &str) -> String {
        norm(line)
            .unwrap()
            .args
            .into_iter()
            .map(|s| s.into_string().unwrap())
            .collect::<Vec<_>>()
            .join(" ")
    }

    #[test]
    fn lab_run_line_is_translated_with_the_lab_defaults() {
        assert_eq!(
            args("-size 200 200 -input a.obj -soft_shadow -num_bounces 5"),
            "raywave render --defaults lab --size 200 200 --input a.obj --shadows soft --bounces 5"
        );
    }

    #[test]
    fn rpi_2023_line_is_translated_with_rpi_defaults() {
        assert_eq!(
            args("--input a.obj --size 300 300 --num_bounces 2 --num_shadow_samples 0"),
            "raywave render --defaults rpi --input a.obj --size 300 300 --bounces 2 --shadows off"
        );
        // --input and --size alone are raywave's spellings too: raywave's defaults.
        assert_eq!(
            args("--input a.obj --size 3 3"),
            "raywave render --input a.obj --size 3 3"
        );
    }

    #[test]
    fn shadow_sample_count_zero_is_no_count_for_the_lab() {
        assert_eq!(
            args("-num_shadow_samples 0"),
            "raywave render --defaults lab"
        );
    }

    #[test]
    fn explicit_defaults_win() {
        assert_eq!(
            args("--defaults raywave -num_bounces 1"),
            "raywave render --defaults raywave --bounces 1"
        );
        assert_eq!(
            args("--num_bounces 1 --defaults=lab"),
            "raywave render --bounces 1 --defaults=lab"
        );
    }

    #[test]
    fn no_effect_flags_give_notes() {
        let n = norm("-sphere_rasterization 16 12 --light-model rpi").unwrap();
        assert_eq!(n.notes.len(), 1);
        assert!(n.notes[0].starts_with("-sphere_rasterization 16 12: accepted, no effect"));
    }

    #[test]
    fn bad_values_mixed_dialects_and_duplicates_are_usage_errors() {
        for line in [
            "-size 200",
            "-size 200 x",
            "-num_bounces -1",
            "-ambient_light 1 nan 1",
            "-num_bounces 1 --num_shadow_samples 2",
            "-num_bounces 1 --bounces 2",
            "-soft_shadow --shadows hard",
            "-frobnicate",
            "-output a.png -o b.png",
            "-input a.obj -i b.obj",
        ] {
            assert!(norm(line).is_err(), "{line}");
        }
    }

    #[test]
    fn clap_messages_name_flags_as_typed_and_escape_controls() {
        let n = norm("-num_bounces 99 -soft_shadow").unwrap();
        assert_eq!(
            n.respell("error: invalid value '99' for '--bounces <BOUNCES>': 99 is not in 0..=64"),
            "error: invalid value '99' for '-num_bounces <BOUNCES>': 99 is not in 0..=64"
        );
        assert_eq!(n.typed("--shadows"), "-soft_shadow");
        assert_eq!(n.typed("--aa"), "--aa");
        assert_eq!(n.respell("a \u{1b}[2J\nb"), "a \\x1b[2J\nb");
    }

    #[test]
    fn no_arguments_means_render() {
        assert_eq!(args(""), "raywave render");
        assert_eq!(args("info"), "raywave info");
        assert_eq!(
            args("scene.obj -o x.png"),
            "raywave render scene.obj -o x.png"
        );
    }
}
