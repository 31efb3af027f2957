//! The committed fixture is reproducible: importing `fixtures/recorded/USA_US101-4_1_T-1.xml`
//! gives the counts and lane changes that `fixtures/recorded/us101-lane-changes.json` holds
//! for it, and that file validates.

use std::path::PathBuf;

use palc_commonroad::import::{RecordedLaneChanges, import_file};

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/recorded")
}

#[test]
fn the_small_us101_scenario_reproduces_its_part_of_the_fixture() {
    let committed = RecordedLaneChanges::read(&fixtures().join("us101-lane-changes.json")).unwrap();
    let imported = import_file(&fixtures().join("USA_US101-4_1_T-1.xml")).unwrap();
    let source = committed
        .sources
        .iter()
        .find(|s| s.file == "USA_US101-4_1_T-1.xml")
        .unwrap();
    assert_eq!(&imported.source, source);
    let committed_changes: Vec<_> = committed
        .lane_changes
        .iter()
        .filter(|c| c.scenario == source.benchmark_id)
        .collect();
    assert_eq!(imported.lane_changes.len(), committed_changes.len());
    for (a, b) in imported.lane_changes.iter().zip(committed_changes) {
        assert_eq!(
            (a.vehicle_id, a.start_time_step, a.end_time_step),
            (b.vehicle_id, b.start_time_step, b.end_time_step)
        );
        assert!((a.lane_width_m - b.lane_width_m).abs() < 1e-9);
        assert_eq!(a.trace.len(), b.trace.len());
    }
}

#[test]
fn the_fixture_counts_add_up() {
    let committed = RecordedLaneChanges::read(&fixtures().join("us101-lane-changes.json")).unwrap();
    let mut sum = palc_commonroad::import::Counts::default();
    for s in &committed.sources {
        sum.add(&s.counts);
    }
    assert_eq!(sum, committed.counts);
    assert_eq!(committed.counts.lane_changes, committed.lane_changes.len());
    for c in &committed.lane_changes {
        assert!(
            (1.0..=6.0).contains(&c.duration_s),
            "{} lasts {} s",
            c.vehicle_id,
            c.duration_s
        );
        assert!(
            (0.5..=2.5).contains(&c.peak_lateral_speed_mps),
            "{}",
            c.peak_lateral_speed_mps
        );
        assert!((3.0..=4.2).contains(&c.lane_width_m), "{}", c.lane_width_m);
    }
}
