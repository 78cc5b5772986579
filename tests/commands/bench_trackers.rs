//! `--export-bmf` and `--export-github-action-benchmark`, the exports for continuous-
//! benchmarking services: every headline figure of every point and engine under its name, with
//! the median and the bounds of its 95% interval read back from the same run's records; both
//! bounds left out without an interval. (tests/commands/schema.rs validates the shapes against
//! docs/schema/.) Tiny images: no timing is asserted.

use super::bench_shards::{SWEEP, ok, read, run};
use serde_json::json;

#[test]
fn the_trackers_exports_carry_each_figures_median_and_interval() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&run(
        d,
        &format!(
            "{SWEEP} --export-json points.json --export-bmf bmf.json --export-github-action-benchmark gab.json"
        ),
    ));
    let records = read(d, "points.json");
    let bmf = read(d, "bmf.json");
    let gab = read(d, "gab.json");
    let gab = gab.as_array().unwrap();
    let mut figures = 0;
    for r in records.as_array().unwrap() {
        let s = &r["setup"]["settings"];
        let point = format!(
            "cornell_box_reflective_spheres {}x{}+s{}+t{}",
            s["width"], s["height"], s["shadow_samples"], r["setup"]["threads"]
        );
        for e in r["engines"].as_array().unwrap() {
            for f in e["summary"].as_array().unwrap() {
                figures += 1;
                let name = format!(
                    "{point} {} {}",
                    e["engine"].as_str().unwrap(),
                    f["figure"].as_str().unwrap()
                );
                let measure = if f["unit"] == "rays/s" {
                    "rays-per-second"
                } else {
                    "rays-per-thread-second"
                };
                assert_eq!(
                    bmf[&name],
                    json!({measure: {"value": f["median"], "lower_value": f["low"], "upper_value": f["high"]}}),
                    "{name}"
                );
                let entry = gab
                    .iter()
                    .find(|g| g["name"] == json!(name))
                    .unwrap_or_else(|| panic!("no github-action-benchmark entry {name}"));
                assert_eq!(entry["unit"], f["unit"]);
                assert_eq!(entry["value"], f["median"]);
                let (m, lo, hi) = (
                    f["median"].as_f64().unwrap(),
                    f["low"].as_f64().unwrap(),
                    f["high"].as_f64().unwrap(),
                );
                let half: f64 = entry["range"]
                    .as_str()
                    .unwrap()
                    .strip_prefix("± ")
                    .unwrap()
                    .parse()
                    .unwrap();
                // Within decimal round-off: the test's JSON reader is not the writer's.
                let expected = (hi - m).max(m - lo);
                assert!((half - expected).abs() <= 1e-12 * expected, "{entry}");
                let extra = entry["extra"].as_str().unwrap();
                let bounds: Vec<f64> = extra
                    .strip_prefix("95% interval of the median: [")
                    .and_then(|x| x.split_once(']'))
                    .unwrap_or_else(|| panic!("{extra}"))
                    .0
                    .split(", ")
                    .map(|x| x.parse().unwrap())
                    .collect();
                assert!((bounds[0] - lo).abs() <= 1e-12 * lo, "{extra}");
                assert!((bounds[1] - hi).abs() <= 1e-12 * hi, "{extra}");
            }
        }
    }
    assert!(figures >= 4 * 2, "{figures}");
    assert_eq!(bmf.as_object().unwrap().len(), figures);
    assert_eq!(gab.len(), figures);
}

#[test]
fn without_an_interval_the_bounds_are_left_out() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&run(
        d,
        "bench --size 16 16 --runs 2 --engine wavefront -q --export-bmf bmf.json \
         --export-github-action-benchmark gab.json",
    ));
    let bmf = read(d, "bmf.json");
    for (name, measures) in bmf.as_object().unwrap() {
        for metric in measures.as_object().unwrap().values() {
            assert!(metric["value"].is_number(), "{name}");
            assert!(metric.get("lower_value").is_none(), "{name}: {metric}");
        }
    }
    for entry in read(d, "gab.json").as_array().unwrap() {
        assert!(entry.get("range").is_none(), "{entry}");
        assert!(
            entry["extra"].as_str().unwrap().contains("no 95% interval"),
            "{entry}"
        );
    }
}
