//! The import never panics: the committed NGSIM scenario cut short anywhere,
//! with numbers replaced by NaN, infinities or huge values, with elements
//! removed, or as arbitrary text, gives an error or a count; what it accepts
//! is a valid file (no NaN travels on into the lane changes).

use palc_commonroad::import::{RecordedLaneChanges, import_str};
use proptest::prelude::*;

fn fixture() -> &'static str {
    static TEXT: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TEXT.get_or_init(|| {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/recorded/USA_US101-4_1_T-1.xml"
        );
        std::fs::read_to_string(path).unwrap_or_default()
    })
}

/// Imports `text`; when it is accepted, the file it makes must validate.
fn import_checked(text: &str, name: &str) -> Result<(), TestCaseError> {
    if let Ok(import) = import_str(text, name) {
        let mut file = RecordedLaneChanges::new();
        file.push(import);
        if let Err(error) = file.validate(std::path::Path::new(name)) {
            return Err(TestCaseError::fail(format!(
                "accepted and invalid: {error}"
            )));
        }
    }
    Ok(())
}

/// Byte offsets of the starts of `<x>`, `<y>`, `<exact>` values.
fn number_starts(text: &str) -> Vec<usize> {
    ["<x>", "<y>", "<exact>"]
        .iter()
        .flat_map(|tag| text.match_indices(tag).map(move |(i, _)| i + tag.len()))
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn a_truncated_scenario_is_an_error_or_a_count(fraction in 0.0f64..1.0) {
        let text = fixture();
        prop_assume!(!text.is_empty());
        let mut cut = (text.len() as f64 * fraction) as usize;
        while !text.is_char_boundary(cut) {
            cut -= 1;
        }
        import_checked(&text[..cut], "truncated.xml")?;
    }

    #[test]
    fn a_scenario_with_odd_numbers_is_an_error_or_a_count(
        picks in prop::collection::vec((any::<prop::sample::Index>(), 0usize..6), 1..20)
    ) {
        let text = fixture();
        prop_assume!(!text.is_empty());
        let starts = number_starts(text);
        let mut positions: Vec<(usize, &str)> = picks
            .iter()
            .map(|(index, kind)| {
                let value = ["NaN", "inf", "-inf", "1e308", "-0", "x"][*kind];
                (starts[index.index(starts.len())], value)
            })
            .collect();
        positions.sort_unstable();
        positions.dedup_by_key(|p| p.0);
        let mut mutated = String::with_capacity(text.len());
        let mut from = 0;
        for (start, value) in positions {
            let end = start + text[start..].find('<').unwrap_or(0);
            mutated.push_str(&text[from..start]);
            mutated.push_str(value);
            from = end;
        }
        mutated.push_str(&text[from..]);
        import_checked(&mutated, "mutated.xml")?;
    }

    #[test]
    fn a_scenario_without_some_elements_is_an_error_or_a_count(
        drops in prop::collection::vec(any::<prop::sample::Index>(), 1..8)
    ) {
        let text = fixture();
        prop_assume!(!text.is_empty());
        let tags: Vec<(usize, usize)> = ["<position>", "<time>", "<shape>", "<successor", "<leftBound>"]
            .iter()
            .flat_map(|tag| {
                let close = format!("</{}>", tag.trim_start_matches('<').trim_end_matches('>'));
                text.match_indices(tag).filter_map(move |(i, _)| {
                    let end = if tag.ends_with('>') {
                        text[i..].find(&close).map(|e| i + e + close.len())?
                    } else {
                        text[i..].find("/>").map(|e| i + e + 2)?
                    };
                    Some((i, end))
                }).collect::<Vec<_>>()
            })
            .collect();
        let mut ranges: Vec<(usize, usize)> = drops.iter().map(|d| tags[d.index(tags.len())]).collect();
        ranges.sort_unstable();
        let mut mutated = String::new();
        let mut from = 0;
        for (start, end) in ranges {
            if start < from {
                continue;
            }
            mutated.push_str(&text[from..start]);
            from = end;
        }
        mutated.push_str(&text[from..]);
        import_checked(&mutated, "dropped.xml")?;
    }

    #[test]
    fn arbitrary_text_is_an_error_or_a_count(text in ".{0,300}") {
        import_checked(&text, "arbitrary.xml")?;
        let wrapped = format!("<commonRoad commonRoadVersion=\"2020a\" timeStepSize=\"0.1\">{text}</commonRoad>");
        import_checked(&wrapped, "wrapped.xml")?;
    }
}
