//! The command line: the lab's three run lines verbatim with the lab's defaults, every lab and
//! RPI flag, whose defaults apply, the no-argument run and the output formats. Its failures
//! (usage errors, scene and output errors caught before the render) are in `cli_errors.rs`.

use crate::common;

use common::bin::{dir_with, files_in, raywave, stderr, stdout, words};
use std::path::Path;
use std::process::Output;

/// The summary line starting with `label`.
fn summary_line(out: &Output, label: &str) -> String {
    stdout(out)
        .lines()
        .find(|l| l.starts_with(label))
        .unwrap_or_else(|| panic!("no `{label}` line in {}", stdout(out)))
        .to_string()
}

fn check_lab_image(dir: &Path, size: (u32, u32)) -> image::RgbImage {
    let img = image::open(dir.join("render.png"))
        .expect("render.png is a readable image")
        .to_rgb8();
    assert_eq!(img.dimensions(), size);
    img
}

/// -background_color 0.2 0.1 0.6 in 8 bits, clamped, no gamma: round(255 · c).
const LAB_BACKGROUND: [u8; 3] = [51, 26, 153];

#[test]
fn lab_run_line_1() {
    let dir = dir_with(&["reflective_spheres.obj"]);
    let line = "-size 200 200 -input reflective_spheres.obj -background_color 0.2 0.1 0.6";
    let out = raywave(dir.path(), &line.split(' ').collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
    let img = check_lab_image(dir.path(), (200, 200));
    // The top-left corner looks over the floor and spheres into the background.
    assert_eq!(img.get_pixel(0, 0).0, LAB_BACKGROUND);
    // The lab's defaults: -num_bounces 0, so the mirrors reflect nothing; hard shadows.
    let stdout = stdout(&out);
    assert!(stdout.contains("200×200, 0 bounces"), "{stdout}");
    assert!(stdout.contains("shadows hard"), "{stdout}");
    assert!(stdout.contains("0 reflection"), "{stdout}");
    assert!(
        stdout.contains("the lab's ArgParser's (--defaults lab) for bounces"),
        "{stdout}"
    );
}

#[test]
fn lab_run_line_2() {
    let dir = dir_with(&["reflective_spheres.obj"]);
    let line = "-size 200 200 -input reflective_spheres.obj -background_color 0.2 0.1 0.6 -num_shadow_samples 10";
    let out = raywave(dir.path(), &line.split(' ').collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
    let img = check_lab_image(dir.path(), (200, 200));
    assert_eq!(img.get_pixel(0, 0).0, LAB_BACKGROUND);
    // The summary says the shadows are soft with 10 points, and no reflections.
    let stdout = stdout(&out);
    assert!(stdout.contains("soft, 10 stratified points"), "{stdout}");
    assert!(stdout.contains("0 bounces"), "{stdout}");
}

#[test]
fn lab_run_line_3() {
    let dir = dir_with(&["cornell_box_reflective_spheres.obj"]);
    let line = "-size 200 200 -input cornell_box_reflective_spheres.obj -soft_shadow -background_color 0.2 0.1 0.6 -num_bounces 5";
    let out = raywave(dir.path(), &line.split(' ').collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
    let img = check_lab_image(dir.path(), (200, 200));
    // The box spans less than the field of view: the corners are background.
    assert_eq!(img.get_pixel(0, 0).0, LAB_BACKGROUND);
    assert_eq!(img.get_pixel(199, 199).0, LAB_BACKGROUND);
    let stdout = stdout(&out);
    assert!(
        stdout.contains("soft") && stdout.contains("5 bounces"),
        "{stdout}"
    );
    // Nothing left to the lab's defaults but those that match raywave's fixed lab look.
    assert!(stdout.contains("ambient 0.2 0.2 0.2"), "{stdout}");
    assert!(stdout.contains("model lab"), "{stdout}");
    // -soft_shadow without a count: the lab's 0 is no count, so raywave's 16 points, and the
    // summary says whose they are.
    assert!(stdout.contains("soft, 16 stratified points"), "{stdout}");
    assert!(
        stdout.contains("(--defaults lab) for shadow samples (raywave's 16), aa, ambient"),
        "{stdout}"
    );
}

#[test]
fn lab_run_line_3_matches_the_no_argument_render_at_the_same_size() {
    // The built-in scene is the lab's third scene with its background: rendering it with no
    // scene argument must give the same image as the lab's run line (both soft, 16 points,
    // 5 bounces).
    let dir = dir_with(&["cornell_box_reflective_spheres.obj"]);
    let line = "-size 64 64 -input cornell_box_reflective_spheres.obj -soft_shadow -background_color 0.2 0.1 0.6 -num_bounces 5 -o lab.png";
    let out = raywave(dir.path(), &line.split(' ').collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
    let out = raywave(dir.path(), &["--size", "64", "64", "-o", "builtin.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let a = image::open(dir.path().join("lab.png")).unwrap().to_rgb8();
    let b = image::open(dir.path().join("builtin.png"))
        .unwrap()
        .to_rgb8();
    assert!(
        a == b,
        "the built-in default differs from the lab's third run line"
    );
}

#[test]
fn no_argument_run_writes_render_png() {
    let dir = tempfile::tempdir().unwrap();
    let out = raywave(dir.path(), &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let img = check_lab_image(dir.path(), (512, 512));
    assert_eq!(img.get_pixel(0, 0).0, LAB_BACKGROUND);
    assert_eq!(files_in(dir.path()), ["render.png"]);
}

#[test]
fn scene_warnings_name_file_and_line_on_stderr() {
    let dir = tempfile::tempdir().unwrap();
    let text = "material\ndiffuse 1 1 1\nm 0\nfrob 1\ns 0 0 0 1\n";
    std::fs::write(dir.path().join("w.obj"), text).unwrap();
    let out = raywave(dir.path(), &["w.obj", "--size", "8", "8", "-o", "w.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("w.obj:4:"), "{}", stderr(&out));
    assert!(dir.path().join("w.png").exists());
}

#[test]
fn hdr_output_is_written_with_the_image() {
    let dir = dir_with(&["cornell_box.obj"]);
    let out = raywave(
        dir.path(),
        &[
            "cornell_box.obj",
            "--size",
            "6",
            "4",
            "-o",
            "a.png",
            "--hdr",
            "a.pfm",
            "--quiet",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let pfm = std::fs::read(dir.path().join("a.pfm")).unwrap();
    let header = b"PF\n6 4\n-1.0\n";
    assert_eq!(&pfm[..header.len()], header);
    assert_eq!(pfm.len(), header.len() + 6 * 4 * 3 * 4);
    assert_eq!(files_in(dir.path()), ["a.pfm", "a.png", "cornell_box.obj"]);
}

#[test]
fn the_built_in_scene_and_its_file_get_the_same_settings() {
    // The built-in scene is the lab's file plus its run line's background: with that
    // background given, the same flags must give the same settings and the same image.
    let dir = dir_with(&["cornell_box_reflective_spheres.obj"]);
    let flags = ["--size", "48", "32", "--background", "0.2", "0.1", "0.6"];
    let builtin = raywave(dir.path(), &[&flags[..], &["-o", "a.png"]].concat());
    assert!(builtin.status.success(), "{}", stderr(&builtin));
    let file = raywave(
        dir.path(),
        &[
            &["cornell_box_reflective_spheres.obj"][..],
            &flags[..],
            &["-o", "b.png"],
        ]
        .concat(),
    );
    assert!(file.status.success(), "{}", stderr(&file));
    for label in ["render", "light", "default", "rays"] {
        assert_eq!(
            summary_line(&builtin, label),
            summary_line(&file, label),
            "{label}"
        );
    }
    // Soft shadows either way (raywave's defaults do not depend on the scene's origin).
    assert!(summary_line(&file, "render").contains("shadows soft"));
    let a = image::open(dir.path().join("a.png")).unwrap().to_rgb8();
    let b = image::open(dir.path().join("b.png")).unwrap().to_rgb8();
    assert!(
        a == b,
        "the built-in scene renders differently from its file"
    );

    // `raywave bench` times the same work for both.
    let bench = |scene: &[&str]| {
        let args = [
            &["bench"][..],
            scene,
            &["--size", "8", "8", "--runs", "1", "--json", "-", "-q"][..],
        ]
        .concat();
        let out = raywave(dir.path(), &args);
        assert!(out.status.success(), "{}", stderr(&out));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let mut settings = json["setup"]["settings"].clone();
        settings["background"] = serde_json::Value::Null; // the scene's, not a flag's
        settings
    };
    assert_eq!(bench(&[]), bench(&["cornell_box_reflective_spheres.obj"]));
}

#[test]
fn every_lab_flag_is_accepted_and_those_without_effect_say_so() {
    let dir = dir_with(&["cornell_box_reflective_spheres.obj"]);
    let line = "-input cornell_box_reflective_spheres.obj -size 24 16 -num_bounces 2 \
                -num_shadow_samples 4 -soft_shadow -background_color 0.2 0.1 0.6 \
                -num_antialias_samples 2 -ambient_light 0.3 0.2 0.1 \
                -cylinder_ring_rasterization 12 -sphere_rasterization 16 12 \
                -num_glossy_samples 4 -num_form_factor_samples 10 -num_photons_to_shoot 1000 \
                -num_photons_to_collect 50 -gather_indirect -output lab.ppm";
    let out = raywave(dir.path(), &words(line));
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    let notes: Vec<&str> = err.lines().filter(|l| l.starts_with("note: ")).collect();
    assert_eq!(notes.len(), 6, "{err}");
    for flag in [
        "-sphere_rasterization 16 12",
        "-num_glossy_samples 4",
        "-num_form_factor_samples 10",
        "-num_photons_to_shoot 1000",
        "-num_photons_to_collect 50",
        "-gather_indirect",
    ] {
        assert!(
            notes
                .iter()
                .any(|n| n.starts_with(&format!("note: {flag}: accepted, no effect in raywave"))),
            "{flag}: {err}"
        );
    }
    let render = summary_line(&out, "render");
    assert!(
        render.contains("24×16, 2 bounces, shadows soft, 4 stratified points per light, 2 aa"),
        "{render}"
    );
    let light = summary_line(&out, "light");
    assert!(light.contains("ambient 0.3 0.2 0.1"), "{light}");
    assert!(light.contains("background 0.2 0.1 0.6 (flag)"), "{light}");
    // The lab's defaults filled only the light model.
    assert_eq!(
        summary_line(&out, "default"),
        "default the lab's ArgParser's (--defaults lab) for light model"
    );
    assert_eq!(
        files_in(dir.path()),
        ["cornell_box_reflective_spheres.obj", "lab.ppm"]
    );
}

#[test]
fn every_rpi_flag_is_accepted_and_rpi_2023_spellings_get_rpi_defaults() {
    let dir = dir_with(&["rpi_ring.obj"]);
    // RPI's older single-dash spellings the lab does not have: the lab's defaults.
    let out = raywave(
        dir.path(),
        &words(
            "-i rpi_ring.obj -size 16 16 -cylinder_ring_rasterization 8 -ambient_light 0.5 0.25 0 -o a.png",
        ),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        summary_line(&out, "scene").contains("34 faces"),
        "{}",
        stdout(&out)
    );
    assert!(summary_line(&out, "light").contains("ambient 0.5 0.25 0"));
    assert!(summary_line(&out, "default").contains("--defaults lab"));

    // RPI 2023's double-dash forms: RPI's defaults (no shadow test, ambient 0.1, RPI's light
    // model); --input and --size are raywave's spellings too.
    let line = "--input rpi_ring.obj --size 20 10 --num_bounces 1 --num_shadow_samples 0 \
                --num_antialias_samples 1 --num_glossy_samples 2 --num_form_factor_samples 3 \
                --sphere_rasterization 8 6 --cylinder_ring_rasterization 10 \
                --num_photons_to_shoot 10 --num_photons_to_collect 5 --gather_indirect -o b.png";
    let out = raywave(dir.path(), &words(line));
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        stderr(&out)
            .lines()
            .filter(|l| l.starts_with("note: --"))
            .count(),
        6,
        "{}",
        stderr(&out)
    );
    assert!(
        summary_line(&out, "scene").contains("42 faces"),
        "{}",
        stdout(&out)
    );
    let render = summary_line(&out, "render");
    assert!(render.contains("20×10, 1 bounces, shadows off"), "{render}");
    let light = summary_line(&out, "light");
    assert!(
        light.contains("model rpi") && light.contains("ambient 0.1 0.1 0.1"),
        "{light}"
    );
    assert!(summary_line(&out, "default").contains("RPI's 2023 ArgParser's (--defaults rpi)"));

    // With a shadow count, RPI's meaning: 1 is hard, more is soft.
    let out = raywave(
        dir.path(),
        &words("--input rpi_ring.obj --size 8 8 --num_shadow_samples 1 -o c.png"),
    );
    assert!(
        summary_line(&out, "render").contains("shadows hard"),
        "{}",
        stdout(&out)
    );
    // With no lab or RPI spelling at all, raywave's defaults.
    let out = raywave(
        dir.path(),
        &words("--input rpi_ring.obj --size 8 8 -o d.png"),
    );
    assert!(summary_line(&out, "render").contains("5 bounces, shadows soft"));
    assert!(summary_line(&out, "default").contains("raywave's"));
}

#[test]
fn raywave_flags_mix_with_lab_spellings_and_win_over_the_lab_defaults() {
    let dir = dir_with(&["reflective_spheres.obj"]);
    let out = raywave(
        dir.path(),
        &words("-size 16 16 -input reflective_spheres.obj --bounces 3 --light-model rpi"),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(summary_line(&out, "render").contains("16×16, 3 bounces, shadows hard"));
    assert!(summary_line(&out, "light").contains("model rpi"));
    let default = summary_line(&out, "default");
    assert!(
        default.contains("--defaults lab") && !default.contains("bounces"),
        "{default}"
    );
    // An explicit --defaults wins over the spellings.
    let out = raywave(
        dir.path(),
        &words("--defaults raywave -size 16 16 -input reflective_spheres.obj"),
    );
    assert!(summary_line(&out, "render").contains("5 bounces, shadows soft"));
    // And the lab's defaults can be asked for with raywave's spellings.
    let out = raywave(dir.path(), &words("reflective_spheres.obj --defaults lab"));
    assert!(summary_line(&out, "render").starts_with("render  100×100, 0 bounces, shadows hard"));
}

#[test]
fn light_model_and_ambient_reach_the_settings() {
    let dir = dir_with(&["cornell_box.obj"]);
    let out = raywave(
        dir.path(),
        &words(
            "cornell_box.obj --size 8 8 --light-model rpi --ambient 0.5 0.25 0 --stats-json s.json -q",
        ),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("s.json")).unwrap()).unwrap();
    assert_eq!(json["settings"]["light_model"], "rpi");
    assert_eq!(
        json["settings"]["ambient"],
        serde_json::json!([0.5, 0.25, 0.0])
    );
    assert_eq!(json["defaults"]["from"], "raywave");
    assert_eq!(
        json["defaults"]["for"],
        serde_json::json!(["bounces", "shadows", "shadow samples", "aa", "background"])
    );
    // The lab's spelling of the ambient light too.
    let out = raywave(
        dir.path(),
        &words("-input cornell_box.obj -size 8 8 -ambient_light 0 0.5 1 --stats-json t.json -q"),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("t.json")).unwrap()).unwrap();
    assert_eq!(
        json["settings"]["ambient"],
        serde_json::json!([0.0, 0.5, 1.0])
    );
    assert_eq!(json["settings"]["light_model"], "lab");

    // `bench` takes the lab's spellings and defaults too.
    let out = raywave(
        dir.path(),
        &words("bench -input cornell_box.obj -size 4 4 -ambient_light 0 0 0 --runs 1 --json - -q"),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["setup"]["settings"]["bounces"], 0);
    assert_eq!(json["setup"]["settings"]["shadows"], "hard");
    assert_eq!(
        json["setup"]["settings"]["ambient"],
        serde_json::json!([0.0, 0.0, 0.0])
    );
    // `bench` and `variance` take --light-model too.
    let out = raywave(
        dir.path(),
        &words("bench cornell_box.obj --size 4 4 --runs 1 --light-model rpi --json - -q"),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["setup"]["settings"]["light_model"], "rpi");
    let out = raywave(
        dir.path(),
        &words(
            "variance cornell_box.obj --size 4 4 --seeds 2 --budgets 1 --samplers random \
             --reference-samples 2 --mask-samples 2 --heatmap-n 1 --no-cache --out rep -q \
             --light-model rpi",
        ),
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn ppm_output_is_a_binary_p6_pixmap() {
    let dir = dir_with(&["cornell_box.obj"]);
    let out = raywave(dir.path(), &words("cornell_box.obj --size 6 4 -o a.ppm -q"));
    assert!(out.status.success(), "{}", stderr(&out));
    let ppm = std::fs::read(dir.path().join("a.ppm")).unwrap();
    let header = b"P6\n6 4\n255\n";
    assert_eq!(&ppm[..header.len()], header);
    assert_eq!(ppm.len(), header.len() + 6 * 4 * 3);
    // The same pixels as the PNG.
    let out = raywave(dir.path(), &words("cornell_box.obj --size 6 4 -o a.png -q"));
    assert!(out.status.success(), "{}", stderr(&out));
    let png = image::open(dir.path().join("a.png")).unwrap().to_rgb8();
    assert_eq!(&ppm[header.len()..], png.as_raw().as_slice());
}

#[test]
fn pfm_and_exr_outputs_are_written_alone() {
    let dir = dir_with(&["cornell_box.obj"]);
    let out = raywave(dir.path(), &words("cornell_box.obj --size 6 4 -o a.pfm"));
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("wrote   a.pfm"), "{}", stdout(&out));
    let pfm = std::fs::read(dir.path().join("a.pfm")).unwrap();
    let header = b"PF\n6 4\n-1.0\n";
    assert_eq!(&pfm[..header.len()], header);
    assert_eq!(pfm.len(), header.len() + 6 * 4 * 3 * 4);
    let out = raywave(dir.path(), &words("cornell_box.obj --size 6 4 -o a.exr -q"));
    assert!(out.status.success(), "{}", stderr(&out));
    let exr = std::fs::read(dir.path().join("a.exr")).unwrap();
    assert_eq!(&exr[..4], &[0x76, 0x2f, 0x31, 0x01], "OpenEXR magic number");
    let img = image::open(dir.path().join("a.exr")).unwrap().to_rgb32f();
    assert_eq!(img.dimensions(), (6, 4));
    // No 8-bit image beside them, and no temporary file left.
    assert_eq!(files_in(dir.path()), ["a.exr", "a.pfm", "cornell_box.obj"]);
}

/// The fraction of pixels with a channel at 255, and with a channel at 16 or more.
fn saturated_and_lit(path: &Path) -> (f64, f64) {
    let img = image::open(path).unwrap().to_rgb8();
    let n = img.pixels().len() as f64;
    let count = |f: &dyn Fn(&[u8; 3]) -> bool| img.pixels().filter(|p| f(&p.0)).count() as f64;
    (
        count(&|p| p.contains(&255)) / n,
        count(&|p| p.iter().any(|&c| c >= 16)) / n,
    )
}

#[test]
fn rpi_style_room_is_blown_out_under_the_lab_light_model() {
    // Its light (ke = 20) is meant for RPI's fall-off; without one it burns the image out.
    let dir = dir_with(&["rpi_style_room.obj"]);
    let out = raywave(
        dir.path(),
        &words("rpi_style_room.obj --size 64 64 --light-model lab -q"),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let (saturated, _) = saturated_and_lit(&dir.path().join("render.png"));
    assert!(saturated > 0.4, "only {saturated} of the pixels saturate");
}

#[test]
fn rpi_style_room_is_not_blown_out_under_the_rpi_light_model() {
    // Under RPI's model (the light's ke·area divided by π·d²) the same room is lit but not
    // burnt: in a simple estimate (direct light from the centroid, ambient 0.2) about 0.5% of
    // the pixels reach 1, the top of the walls next to the light.
    let dir = dir_with(&["rpi_style_room.obj"]);
    let out = raywave(
        dir.path(),
        &words("rpi_style_room.obj --size 64 64 --light-model rpi -q"),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let (saturated, lit) = saturated_and_lit(&dir.path().join("render.png"));
    assert!(saturated < 0.05, "{saturated} of the pixels saturate");
    assert!(lit > 0.5, "only {lit} of the pixels are lit");
}

#[test]
fn stats_tables_give_each_kind_over_its_own_thread_time_the_total_over_the_wall_clock_and_the_phases()
 {
    for (engine, timed_by) in [
        ("wavefront", "kinds timed by the stage timers"),
        ("reference", "kinds timed by a second pass with timers"),
    ] {
        let dir = dir_with(&["cornell_box_reflective_spheres.obj"]);
        let line =
            format!("cornell_box_reflective_spheres.obj --size 16 12 --engine {engine} --stats");
        let out = raywave(dir.path(), &words(&line));
        assert!(out.status.success(), "{}", stderr(&out));
        let text = stdout(&out);
        let row = |kind: &str| -> Vec<String> {
            text.lines()
                .find(|l| l.split_whitespace().next() == Some(kind))
                .unwrap_or_else(|| panic!("no `{kind}` row in:\n{text}"))
                .split_whitespace()
                .map(str::to_string)
                .collect()
        };
        assert_eq!(
            row("kind"),
            ["kind", "rays", "thread-s", "Mrays/thread-s"],
            "{text}"
        );
        for kind in ["camera", "shadow", "reflection"] {
            let r = row(kind);
            // rays, thread-seconds, Mrays per thread-second: all measured, for both engines.
            assert_eq!(r.len(), 4, "{text}");
            assert!(r[3].parse::<f64>().is_ok_and(|x| x > 0.0), "{kind}: {text}");
        }
        assert!(text.contains("wall s") && text.contains(timed_by), "{text}");
        // The phases before the first ray and after the last, in milliseconds, and when the
        // first ray was cast: the set-up phases add up to it.
        let phases: Vec<&str> = text
            .lines()
            .skip_while(|l| l.split_whitespace().collect::<Vec<_>>() != ["phase", "ms"])
            .collect();
        let ms = |phase: &str| -> f64 {
            let line = phases
                .iter()
                .find(|l| l.starts_with(phase))
                .unwrap_or_else(|| panic!("no `{phase}` phase in:\n{text}"));
            line[phase.len()..].trim().parse().expect("milliseconds")
        };
        let setup: f64 = [
            "arguments and signals",
            "outputs, scene, settings",
            "thread pool",
            "memory check",
            "tables, BVH, progress bar",
        ]
        .map(ms)
        .iter()
        .sum();
        assert!(
            ms("render") > 0.0 && ms("tone map, encode, write") > 0.0,
            "{text}"
        );
        let first = text
            .lines()
            .find_map(|l| l.strip_prefix("first ray "))
            .and_then(|l| l.split(' ').next())
            .and_then(|x| x.parse::<f64>().ok())
            .unwrap_or_else(|| panic!("no `first ray` line in:\n{text}"));
        assert!(
            (first - setup).abs() <= 0.01,
            "{first} against {setup}: {text}"
        );
        // The total is its rays over the wall-clock seconds of the summary's `time` line.
        let total = row("total");
        let rays: f64 = total[1].parse().unwrap();
        let seconds: f64 = total[2].parse().unwrap();
        let rate: f64 = total[3].parse().unwrap();
        // Both are printed rounded (seconds to 0.001, the rate to 0.01): the rate must lie
        // between the rates of the seconds' rounding interval, give or take its own rounding.
        if seconds > 0.0005 {
            let (fastest, slowest) = (rays / (seconds - 0.0005), rays / (seconds + 0.0005));
            assert!(
                (slowest / 1e6 - 0.005..=fastest / 1e6 + 0.005).contains(&rate),
                "{text}"
            );
        }
        // The wavefront engine names its shadow stage's path (soft shadows on the lab box:
        // fused block by block); the reference has none.
        let path = text.lines().find(|l| l.starts_with("shadow path "));
        match engine {
            "wavefront" => assert!(
                path.is_some_and(|l| l.starts_with("shadow path FusedSoft: ")),
                "{text}"
            ),
            _ => assert_eq!(path, None, "{text}"),
        }
    }
}

/// `--stats` and `--stats-json` name the shadow path each kind of render takes: hard shadows
/// fused N hits at a time (on a mesh too, through the BVH), soft shadows on a mesh through the
/// queue.
#[test]
fn stats_name_the_shadow_path_that_ran() {
    let dir = dir_with(&[
        "cornell_box_reflective_spheres.obj",
        "mesh_spheres_small.obj",
    ]);
    for (line, path) in [
        (
            "cornell_box_reflective_spheres.obj --shadows hard",
            "FusedHard",
        ),
        ("mesh_spheres_small.obj --shadows hard", "FusedHard"),
        ("mesh_spheres_small.obj --shadows soft", "QueuedPerHit"),
    ] {
        let line = format!("{line} --size 16 12 --stats --stats-json stats.json -q");
        let out = raywave(dir.path(), &words(&line));
        assert!(out.status.success(), "{line}: {}", stderr(&out));
        let text = stdout(&out);
        assert!(
            text.lines()
                .any(|l| l.starts_with(&format!("shadow path {path}: "))),
            "{line}: expected the {path} path in:\n{text}"
        );
        let json = std::fs::read_to_string(dir.path().join("stats.json")).unwrap();
        let record: serde_json::Value = serde_json::from_str(&json).unwrap();
        assert_eq!(record["shadow_path"], path, "{line}: {json}");
    }
}

/// `--lanes 8` and `--lanes 16` write the same image bytes, and the summary, the
/// `--stats-json` record and `raywave info` name the path that ran.
#[test]
fn lane_widths_give_the_same_image_and_name_their_path() {
    let dir = dir_with(&["cornell_box_reflective_spheres.obj"]);
    let render = |lanes: &str| {
        let png = format!("lanes{lanes}.png");
        let json = format!("lanes{lanes}.json");
        let out = raywave(
            dir.path(),
            &[
                "render",
                "cornell_box_reflective_spheres.obj",
                "--size",
                "48",
                "40",
                "--bounces",
                "3",
                "--shadows",
                "soft",
                "--shadow-samples",
                "24",
                "--lanes",
                lanes,
                "-o",
                &png,
                "--stats-json",
                &json,
            ],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let record: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join(&json)).unwrap()).unwrap();
        (
            std::fs::read(dir.path().join(&png)).unwrap(),
            summary_line(&out, "raywave"),
            record["simd"].as_str().unwrap().to_string(),
        )
    };
    let (png8, line8, simd8) = render("8");
    let (png16, line16, simd16) = render("16");
    assert!(png8 == png16, "--lanes 16 changed the image");
    assert!(simd8.contains("f32x8"), "{simd8}");
    assert!(simd16.contains("f32x16"), "{simd16}");
    assert!(line8.contains(&format!("simd {simd8}")), "{line8}");
    assert!(line16.contains(&format!("simd {simd16}")), "{line16}");
    let (auto, _, simd_auto) = render("auto");
    assert!(auto == png8);
    let info = stdout(&raywave(dir.path(), &["info"]));
    assert!(info.contains(&format!("simd    {simd_auto}")), "{info}");
    let lanes = if simd_auto.contains("f32x16") { 16 } else { 8 };
    assert!(
        info.contains(&format!("lanes   {lanes} by default")),
        "{info}"
    );
    // Not a width.
    let out = raywave(dir.path(), &["render", "--lanes", "4"]);
    assert!(!out.status.success());
}
