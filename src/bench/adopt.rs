//! `--compare NAME` measures what the record measured: every setting, the thread count and
//! the engines come from the record, except those the user gave on the command line (the
//! command line tells which: clap's `ArgMatches::value_source`). A flag given explicitly that
//! differs from the record makes the setups differ, and the comparison is refused.

use crate::render::settings::RenderSettings;

/// The settings fields each image flag sets (as named in the record's JSON). `--defaults`
/// sets them all: given explicitly, nothing is adopted. Fields no flag names (the seed) are
/// always adopted.
const FLAG_FIELDS: [(&str, &[&str]); 10] = [
    ("size", &["width", "height"]),
    ("bounces", &["bounces"]),
    ("shadows", &["shadows"]),
    // --shadow-samples alone also decides the shadow mode (1 point: hard, more: soft).
    ("shadow_samples", &["shadow_samples", "shadows"]),
    ("sampler", &["sampler"]),
    ("aa", &["aa_samples"]),
    ("background", &["background"]),
    ("ambient", &["ambient"]),
    ("light_model", &["light_model"]),
    ("defaults", &["*"]),
];

/// `ours` with every field that no flag in `explicit` (clap ids: `size`, `shadow_samples`,
/// ...) set taken from `record`.
pub(crate) fn adopt_settings(
    ours: &RenderSettings,
    record: &RenderSettings,
    explicit: &[String],
) -> RenderSettings {
    let kept: Vec<&str> = FLAG_FIELDS
        .iter()
        .filter(|(flag, _)| explicit.iter().any(|e| e == flag))
        .flat_map(|(_, fields)| fields.iter().copied())
        .collect();
    if kept.contains(&"*") {
        return ours.clone();
    }
    let (Ok(serde_json::Value::Object(mut mine)), Ok(serde_json::Value::Object(theirs))) =
        (serde_json::to_value(ours), serde_json::to_value(record))
    else {
        return ours.clone();
    };
    for (key, value) in theirs {
        if !kept.contains(&key.as_str()) {
            mine.insert(key, value);
        }
    }
    serde_json::from_value(serde_json::Value::Object(mine)).unwrap_or_else(|_| ours.clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unset_flags_are_adopted_and_explicit_ones_kept() {
        let ours = RenderSettings::default();
        let mut record = RenderSettings::preview();
        record.bounces = 7;
        record.width = 33;
        let adopted = adopt_settings(&ours, &record, &[]);
        assert_eq!(adopted, record);
        let kept = adopt_settings(&ours, &record, &["bounces".to_string()]);
        assert_eq!((kept.bounces, kept.width), (ours.bounces, 33));
        let all = adopt_settings(&ours, &record, &["defaults".to_string()]);
        assert_eq!(all, ours);
    }
}
