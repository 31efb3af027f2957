//! Deterministic run ids: a run is named by a hash of what it runs, not by its
//! place in the plan, so the same run has the same id in the quick and the full
//! config, in every shard and in every re-run.
//!
//! The key is the experiment, method, rung, user kind, driver or style, speed
//! case (with its speeds), headway, seed, step and horizon margin; a run that
//! starts from another run's experience adds that run's id, so a chain of runs
//! is named by all of its links. The id is the first [`ID_HEX`] hex digits of
//! the key's SHA-256.

use std::collections::HashMap;

use sha2::{Digest, Sha256};

use crate::plan::RunSpec;

/// Hex digits of a run id: 64 bits, far from a collision at any plan size the
/// evaluation accepts.
pub const ID_HEX: usize = 16;

/// The text the id of `spec` hashes, `source` being the id of the run it starts
/// from; one `field=value` per line, in a fixed order.
pub fn key(spec: &RunSpec, source: Option<&str>) -> String {
    let option = |v: Option<f64>| v.map_or_else(String::new, |v| v.to_string());
    let case = &spec.speed_case;
    let fields = [
        ("experiment", spec.experiment.name().to_owned()),
        ("method", spec.method.name().to_owned()),
        ("rung", spec.rung.clone().unwrap_or_default()),
        ("user", spec.user.name.clone()),
        ("style", spec.style_name().to_owned()),
        (
            "speed_case",
            format!("{} {} {}", case.name, case.ego_mph, case.others_mph),
        ),
        ("headway_m", spec.headway_m.to_string()),
        ("seed", spec.seed.to_string()),
        ("dt", option(spec.dt)),
        ("horizon_margin_s", option(spec.horizon_margin_s)),
        ("source", source.unwrap_or_default().to_owned()),
    ];
    let mut text = String::new();
    for (name, value) in fields {
        text.push_str(name);
        text.push('=');
        text.push_str(&value);
        text.push('\n');
    }
    text
}

/// The id of a key.
fn hash(key: &str) -> String {
    let digest = Sha256::digest(key.as_bytes());
    (digest.iter().take(ID_HEX / 2))
        .map(|byte| format!("{byte:02x}"))
        .collect()
}

/// The ids of `specs`, in their order; `experience_from` is looked up by
/// `RunSpec::id` among `specs`. A run whose source is missing (or a source
/// chain that loops) is named without the source's id.
pub fn run_ids<'a>(specs: impl IntoIterator<Item = &'a RunSpec>) -> Vec<String> {
    let specs: Vec<&RunSpec> = specs.into_iter().collect();
    let by_id: HashMap<usize, &RunSpec> = specs.iter().map(|s| (s.id, *s)).collect();
    let mut ids: HashMap<usize, String> = HashMap::new();
    specs
        .iter()
        .map(|spec| id_of(spec, &by_id, &mut ids, by_id.len()))
        .collect()
}

/// The id of `spec`, its sources' ids computed first (at most `depth` links).
fn id_of(
    spec: &RunSpec,
    by_id: &HashMap<usize, &RunSpec>,
    ids: &mut HashMap<usize, String>,
    depth: usize,
) -> String {
    if let Some(id) = ids.get(&spec.id) {
        return id.clone();
    }
    let source = (spec.experience_from)
        .filter(|_| depth > 0)
        .and_then(|from| by_id.get(&from))
        .map(|source| id_of(source, by_id, ids, depth - 1));
    let id = hash(&key(spec, source.as_deref()));
    ids.insert(spec.id, id.clone());
    id
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Evaluation;
    use crate::plan::{Experiment, expand};
    use std::path::Path;

    #[test]
    fn an_id_is_sixteen_hex_digits_and_names_the_key() {
        let plan = expand(
            &crate::plan::tests::selection(),
            &crate::plan::tests::testbed(),
        )
        .unwrap();
        let ids = run_ids(plan.all());
        assert_eq!(ids.len(), plan.len());
        assert!(
            ids.iter()
                .all(|id| id.len() == ID_HEX && id.chars().all(|c| c.is_ascii_hexdigit()))
        );
        // The same plan expanded again gives the same ids.
        let again = expand(
            &crate::plan::tests::selection(),
            &crate::plan::tests::testbed(),
        )
        .unwrap();
        assert_eq!(ids, run_ids(again.all()));
    }

    #[test]
    fn another_experiment_or_source_is_another_id() {
        let plan = expand(
            &crate::plan::tests::selection(),
            &crate::plan::tests::testbed(),
        )
        .unwrap();
        let spec = plan.first[0].clone();
        let mut other = spec.clone();
        other.experiment = Experiment::ClosedLoop;
        assert_ne!(run_ids([&spec]), run_ids([&other]));
        let (mut from_a, mut from_b) = (spec.clone(), spec.clone());
        from_a.id = 10;
        from_b.id = 10;
        from_a.experience_from = Some(0);
        from_b.experience_from = Some(1);
        let mut source_b = plan.first[1].clone();
        source_b.id = 1;
        let mut source_a = spec.clone();
        source_a.id = 0;
        let a = run_ids([&source_a, &source_b, &from_a]);
        let b = run_ids([&source_a, &source_b, &from_b]);
        assert_ne!(a[2], b[2]);
        // Without its source, a run with experience is not the run from scratch.
        assert_ne!(a[2], a[0]);
    }

    /// The shipped reproduction: every run of the full plan has its own id, and
    /// every run of the quick plan has the id of the same run in the full plan.
    #[test]
    fn ids_are_unique_in_the_full_plan_and_shared_with_the_quick_plan() {
        let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/reproduce.toml");
        let full = Evaluation::load(&config, false).unwrap().plan().unwrap();
        let full_ids = run_ids(full.all());
        let mut keys: HashMap<&str, String> = HashMap::new();
        let full_specs: Vec<&RunSpec> = full.all().collect();
        for (id, spec) in full_ids.iter().zip(&full_specs) {
            if let Some(before) = keys.insert(id, spec.label()) {
                panic!("{id} twice: {before} and {}", spec.label());
            }
        }
        let quick = Evaluation::load(&config, true).unwrap().plan().unwrap();
        let quick_ids = run_ids(quick.all());
        let mut shared = 0;
        for (id, spec) in quick_ids.iter().zip(quick.all()) {
            if let Some(label) = keys.get(id.as_str()) {
                assert_eq!(*label, spec.label());
                shared += 1;
            }
        }
        // The quick grid is a subset of the full one: its grid runs are all there.
        let quick_grid = quick.all().filter(|s| s.experiment == Experiment::Grid);
        assert!(shared >= quick_grid.count(), "{shared} shared");
    }
}
