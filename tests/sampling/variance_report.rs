//! What `raywave variance` writes, read back from the files: per-seed rows in `seeds.csv` and
//! `results.json` that pool to the summary rows, a `results.json` whose keys are the documented
//! ones, heat maps with a colour bar, a contact sheet with one tile per sampler and budget; and
//! its flags: `--budgets` in both the comma form and the form its own --help shows, and a
//! `--heatmap-n` that is not a budget (the nearest is drawn, with a note).

use crate::common;

use common::bin::{raywave, stderr, stdout};
use raywave::output::false_colour::{MIN_SIDE, inferno};
use raywave::variance::command::nearest_budget;
use raywave::variance::report::sheet::{MIN_TILE, contact_sheet};
use std::path::Path;

/// A small, quick study: 16×16, 3 seeds, cheap reference and mask.
const QUICK: [&str; 9] = [
    "variance",
    "--size",
    "16",
    "16",
    "--seeds",
    "3",
    "--reference-samples",
    "64",
    "--no-cache",
];

fn run(dir: &Path, extra: &[&str]) -> std::process::Output {
    let mut args: Vec<&str> = QUICK.to_vec();
    args.extend(["--mask-samples", "16", "-q"]);
    args.extend(extra);
    let out = raywave(dir, &args);
    assert!(
        out.status.success(),
        "raywave {}: {}\n{}",
        args.join(" "),
        stdout(&out),
        stderr(&out)
    );
    out
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn the_nearest_budget_is_nearest_on_a_log_scale() {
    let b = [1, 4, 16, 64];
    assert_eq!(nearest_budget(&b, 16), Some(16));
    assert_eq!(nearest_budget(&b, 10), Some(16)); // 10/4 = 2.5, 16/10 = 1.6
    assert_eq!(nearest_budget(&b, 6), Some(4)); // 6/4 = 1.5, 16/6 = 2.7
    assert_eq!(nearest_budget(&b, 2), Some(1)); // a tie (×2 either way): the smaller
    assert_eq!(nearest_budget(&b, 1000), Some(64));
    assert_eq!(nearest_budget(&b, 0), Some(1));
    assert_eq!(nearest_budget(&[], 8), None);
}

#[test]
fn a_heatmap_budget_that_is_not_a_budget_draws_the_nearest() {
    let dir = tempfile::tempdir().unwrap();
    let out = run(
        dir.path(),
        &[
            "--budgets",
            "4,16",
            "--samplers",
            "random",
            "--heatmap-n",
            "10",
        ],
    );
    let err = stderr(&out);
    assert!(
        err.contains("--heatmap-n 10") && err.contains("N = 16"),
        "{err}"
    );
    let report = dir.path().join("variance-report");
    assert!(report.join("heat_random_N16.png").is_file());
    assert_eq!(
        json(&report.join("results.json"))["settings"]["study"]["heatmap_n"],
        16
    );
}

/// The default's form in --help, the comma form and the space form all give the same budgets.
#[test]
fn budgets_take_the_form_help_shows_and_commas() {
    let dir = tempfile::tempdir().unwrap();
    let help = stdout(&raywave(dir.path(), &["variance", "--help"]));
    let shown = help
        .split("--budgets <BUDGETS>")
        .nth(1)
        .and_then(|rest| rest.split("[default: ").nth(1))
        .and_then(|rest| rest.split(']').next())
        .expect("--help shows the default budgets")
        .to_string();
    assert_eq!(shown, "1 4 16 64 256", "{help}");
    let forms: [Vec<&str>; 3] = [
        shown.split_whitespace().collect(),
        vec!["1,4,16,64,256"],
        vec!["1,4", "16", "64,256"],
    ];
    for (i, form) in forms.iter().enumerate() {
        let out_dir = format!("r{i}");
        let mut extra = vec!["--samplers", "random", "--out", &out_dir, "--budgets"];
        extra.extend(form.iter().copied());
        run(dir.path(), &extra);
        let doc = json(&dir.path().join(&out_dir).join("results.json"));
        assert_eq!(
            doc["settings"]["study"]["budgets"],
            serde_json::json!([1, 4, 16, 64, 256]),
            "--budgets {}",
            form.join(" ")
        );
    }
    // Samplers take both forms too.
    run(
        dir.path(),
        &[
            "--samplers",
            "random",
            "lab",
            "--budgets",
            "4",
            "--out",
            "s",
        ],
    );
    let doc = json(&dir.path().join("s/results.json"));
    assert_eq!(
        doc["settings"]["study"]["samplers"],
        serde_json::json!(["random", "lab"])
    );
}

#[test]
fn per_seed_rows_pool_to_the_summary_and_the_json_says_what_it_holds() {
    let dir = tempfile::tempdir().unwrap();
    run(
        dir.path(),
        &[
            "--budgets",
            "1,4",
            "--samplers",
            "random,lab",
            "--heatmap-n",
            "4",
        ],
    );
    let report = dir.path().join("variance-report");
    let seeds = std::fs::read_to_string(report.join("seeds.csv")).unwrap();
    let lines: Vec<&str> = seeds.lines().collect();
    assert_eq!(lines[0], "sampler,n,region,seed,mse,bias,seconds");
    // 2 samplers × 2 budgets × 3 regions × 3 seeds.
    assert_eq!(lines.len(), 1 + 2 * 2 * 3 * 3);
    let summary = std::fs::read_to_string(report.join("results.csv")).unwrap();
    let header: Vec<&str> = summary.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    for name in ["mse_low", "mse_high", "seconds_low", "efficiency_low"] {
        col(name);
    }
    for row in summary.lines().skip(1) {
        let f: Vec<&str> = row.split(',').collect();
        let key = format!("{},{},{},", f[0], f[1], f[2]);
        let per: Vec<f64> = lines
            .iter()
            .filter(|l| l.starts_with(&key))
            .map(|l| l.split(',').nth(4).unwrap().parse().unwrap())
            .collect();
        assert_eq!(per.len(), 3, "{key}");
        let mse: f64 = f[col("mse")].parse().unwrap();
        let mean = per.iter().sum::<f64>() / 3.0;
        assert!(
            (mean - mse).abs() <= 1e-9 * mse.max(1e-30),
            "{key}: {mean} vs {mse}"
        );
        // Lab at N = 1 renders the same image for every seed: not fitted.
        let excluded = f[col("excluded_from_fit")] == "true";
        assert_eq!(excluded, f[0] == "lab" && f[1] == "1", "{row}");
    }

    let doc = json(&report.join("results.json"));
    let object = doc.as_object().unwrap();
    let fields = doc["schema"]["fields"].as_object().unwrap();
    let keys: Vec<&String> = object.keys().collect();
    let documented: Vec<&String> = fields.keys().collect();
    assert_eq!(
        {
            let mut k = keys.clone();
            k.sort();
            k
        },
        documented,
        "every key documented, every documented key present"
    );
    for key in [
        "schema",
        "raywave_version",
        "commit",
        "commit_dirty",
        "created",
        "machine",
        "settings",
        "region_pixels",
        "reference_mse",
        "rows",
        "slopes",
        "matching",
        "seeds",
        "outputs",
    ] {
        assert!(object.contains_key(key), "results.json lacks {key}");
    }
    assert!(doc["schema"]["version"].as_u64().unwrap() >= 2);
    assert_eq!(doc["raywave_version"], env!("CARGO_PKG_VERSION"));
    assert!(doc["machine"]["logical_cpus"].as_u64().unwrap() >= 1);
    assert_eq!(doc["settings"]["study"]["seeds"], 3);
    assert_eq!(doc["settings"]["study"]["base"]["width"], 16);
    assert!(doc["settings"]["bootstrap"]["resamples"].as_u64().unwrap() >= 1000);
    assert_eq!(doc["seeds"].as_array().unwrap().len(), 2 * 2 * 3 * 3);
    let row = &doc["rows"][0];
    for key in [
        "mse",
        "mse_interval",
        "seconds",
        "seconds_interval",
        "efficiency",
        "efficiency_interval",
        "excluded_from_fit",
    ] {
        assert!(row.get(key).is_some(), "rows lack {key}: {row}");
    }
    let lab_whole = doc["slopes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["sampler"] == "lab" && s["region"] == "whole")
        .unwrap();
    assert_eq!(lab_whole["excluded"], serde_json::json!([1]));
    assert_eq!(lab_whole["fitted"], serde_json::json!([4]));
    // Every file the report names exists, the spectra among them.
    for name in doc["outputs"].as_object().unwrap().keys() {
        assert!(report.join(name).is_file(), "{name}");
    }
    for name in [
        "perceived.csv",
        "spectra.csv",
        "spectrum_N1.png",
        "spectrum_N4.png",
    ] {
        assert!(doc["outputs"].get(name).is_some(), "outputs lack {name}");
    }
    // The perceived figures: finite, with intervals; random's low band is 1× random's.
    for row in doc["rows"].as_array().unwrap() {
        let p = &row["perceived"];
        assert_eq!(p["spectrum"].as_array().unwrap().len(), 32, "{row}");
        for key in ["low_band_power", "low_band_share"] {
            assert!(p[key].as_f64().is_some_and(f64::is_finite), "{key}: {p}");
        }
        assert_eq!(p["lowpass_mse"].as_array().unwrap().len(), 2);
        if row["sampler"] == "random" && row["region"] != "lit" {
            assert_eq!(p["low_band_vs_random"].as_f64(), Some(1.0), "{p}");
        }
    }
    let perceived = std::fs::read_to_string(report.join("perceived.csv")).unwrap();
    assert!(perceived.starts_with("sampler,n,region,lowpass1_mse,"));
    assert_eq!(perceived.lines().count(), 1 + 2 * 2 * 3);
    let spectra = std::fs::read_to_string(report.join("spectra.csv")).unwrap();
    assert_eq!(spectra.lines().count(), 1 + 2 * 2 * 3 * 32);
    let table = std::fs::read_to_string(report.join("table.txt")).unwrap();
    assert!(table.contains("where the error sits"), "{table}");
}

/// The heat map's colour bar: columns right of the map that run from the map's brightest
/// colour at the top to its darkest at the bottom, over most of the map's height, getting no
/// brighter on the way down (but for the rounding of the colour map's channels).
#[test]
fn heat_maps_carry_a_colour_bar_and_the_contact_sheet_a_tile_per_run() {
    let dir = tempfile::tempdir().unwrap();
    run(
        dir.path(),
        &[
            "--budgets",
            "1,4,16",
            "--samplers",
            "random,stratified",
            "--heatmap-n",
            "4",
        ],
    );
    let report = dir.path().join("variance-report");
    let heat = image::open(report.join("heat_stratified_N4.png"))
        .unwrap()
        .to_rgb8();
    let map_side = 16 * MIN_SIDE.div_ceil(16);
    let (top, bottom) = (inferno(1.0), inferno(0.0));
    let lum = |p: [u8; 3]| p.iter().map(|&c| c as u32).sum::<u32>();
    let bar_columns = (map_side..heat.width())
        .filter(|&x| {
            let col: Vec<[u8; 3]> = (0..heat.height()).map(|y| heat.get_pixel(x, y).0).collect();
            let (Some(y0), Some(y1)) = (
                col.iter().position(|&p| p == top),
                col.iter().rposition(|&p| p == bottom),
            ) else {
                return false;
            };
            y1 > y0 + (map_side * 9 / 10) as usize
                && col[y0..=y1].windows(2).all(|w| lum(w[1]) <= lum(w[0]) + 3)
        })
        .count();
    assert!(bar_columns >= 10, "{bar_columns} colour-bar columns");
    assert!(heat.width() > map_side + 40 && heat.height() > map_side + 20);

    let sheet = image::open(report.join("contact_sheet.png"))
        .unwrap()
        .to_rgb8();
    let tile = 16 * MIN_TILE.div_ceil(16);
    assert!(
        sheet.width() >= 3 * tile && sheet.width() < 3 * tile + 400,
        "{}",
        sheet.width()
    );
    assert!(
        sheet.height() >= 2 * tile && sheet.height() < 2 * tile + 200,
        "{}",
        sheet.height()
    );
}

/// The sheet puts image (row r, column c) at row r and column c, enlarged by a whole factor,
/// each pixel kept: solid images of distinct colours show up as rectangles of that size in
/// row-major order.
#[test]
fn the_contact_sheet_lays_out_one_tile_per_sampler_and_budget() {
    let (w, h) = (20u32, 10u32);
    let colours = [
        [250, 0, 0],
        [0, 250, 0],
        [0, 0, 250],
        [250, 250, 0],
        [0, 250, 250],
        [250, 0, 250],
    ];
    let images: Vec<image::RgbImage> = colours
        .iter()
        .map(|&c| image::RgbImage::from_pixel(w, h, image::Rgb(c)))
        .collect();
    let grid: Vec<Vec<&image::RgbImage>> = images.chunks(3).map(|r| r.iter().collect()).collect();
    let rows = vec!["random".to_string(), "sobol".to_string()];
    let cols: Vec<String> = ["N = 1", "N = 4", "N = 16"].map(String::from).to_vec();
    let sheet = contact_sheet("t", &rows, &cols, &grid).unwrap();
    let factor = MIN_TILE.div_ceil(h);
    let (tw, th) = (w * factor, h * factor);
    let mut boxes = Vec::new();
    for c in colours {
        let pts: Vec<(u32, u32)> = sheet
            .enumerate_pixels()
            .filter(|(_, _, p)| p.0 == c)
            .map(|(x, y, _)| (x, y))
            .collect();
        assert_eq!(pts.len() as u32, tw * th, "{c:?}");
        let x0 = pts.iter().map(|p| p.0).min().unwrap();
        let y0 = pts.iter().map(|p| p.1).min().unwrap();
        let x1 = pts.iter().map(|p| p.0).max().unwrap();
        let y1 = pts.iter().map(|p| p.1).max().unwrap();
        assert_eq!((x1 - x0 + 1, y1 - y0 + 1), (tw, th), "{c:?}");
        boxes.push((x0, y0));
    }
    for r in 0..2 {
        for c in 0..3 {
            let (x, y) = boxes[r * 3 + c];
            if c > 0 {
                assert!(x >= boxes[r * 3 + c - 1].0 + tw && y == boxes[r * 3].1);
            }
            if r > 0 {
                assert!(y >= boxes[c].1 + th && x == boxes[c].0);
            }
        }
    }
    assert!(sheet.width() >= 3 * tw && sheet.height() >= 2 * th);
    // Mismatched sizes are refused, not drawn.
    let small = image::RgbImage::new(4, 4);
    let bad = vec![vec![&images[0], &small, &images[1]], grid[1].clone()];
    assert!(contact_sheet("t", &rows, &cols, &bad).is_err());
}
