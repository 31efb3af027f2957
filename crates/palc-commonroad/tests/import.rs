//! The importer on synthetic scenarios written here: a straight two-lane road of lanelets
//! with successors, vehicles keeping their lanes, one quintic lane change with 3 cm of
//! deterministic noise, one cut by the recording's end, one with a gap in its time steps
//! and one with a NaN; then every error, and the lane change's invariance under rotating
//! and translating the whole scenario.

use std::fmt::Write as _;

use palc_commonroad::import::{
    CentreSource, Direction, ImportError, ReadError, RecordedLaneChanges, ScenarioImport,
    SkipReason, import_file, import_str,
};
use proptest::prelude::*;

const DT: f64 = 0.1;
const LANE_WIDTH: f64 = 3.6;
const SPEED: f64 = 25.0;
const STEPS: usize = 200;
/// The quintic lane change of vehicle 10: start and duration (s).
const LC_START: f64 = 8.0;
const LC_DURATION: f64 = 5.0;

/// A rigid motion of the plane: rotation by `angle`, then translation.
#[derive(Debug, Clone, Copy)]
struct Pose {
    angle: f64,
    tx: f64,
    ty: f64,
}

impl Pose {
    const IDENTITY: Self = Self {
        angle: 0.0,
        tx: 0.0,
        ty: 0.0,
    };

    fn apply(self, x: f64, y: f64) -> (f64, f64) {
        let (s, c) = self.angle.sin_cos();
        (c * x - s * y + self.tx, s * x + c * y + self.ty)
    }
}

/// Uniform in [-1, 1], a fixed function of `i` (splitmix64).
fn unit_noise(i: u64) -> f64 {
    let mut z = i.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
}

/// Noise with a standard deviation of 3 cm (uniform on ±3√3 cm).
fn noise(vehicle: i64, step: usize) -> f64 {
    0.03 * 3f64.sqrt() * unit_noise((vehicle as u64) << 20 | step as u64)
}

/// The quintic `10τ³ - 15τ⁴ + 6τ⁵` at time `t` of a lane change starting at `start`.
fn quintic(t: f64, start: f64, duration: f64) -> f64 {
    let tau = ((t - start) / duration).clamp(0.0, 1.0);
    tau.powi(3) * (10.0 - 15.0 * tau + 6.0 * tau * tau)
}

/// A recorded vehicle in road coordinates: `x(step)`, `y(step)` (m), `None` for a missing
/// step; `x` and `y` may be NaN.
struct Vehicle {
    id: i64,
    samples: Vec<(usize, f64, f64)>,
}

fn keeper(id: i64, x0: f64, lane: usize) -> Vehicle {
    let samples = (0..STEPS)
        .map(|k| {
            let x = x0 + SPEED * k as f64 * DT;
            (k, x, lane as f64 * LANE_WIDTH + noise(id, k))
        })
        .collect();
    Vehicle { id, samples }
}

fn changer(id: i64, x0: f64, from: usize, to: usize, start: f64, steps: usize) -> Vehicle {
    let samples = (0..steps)
        .map(|k| {
            let t = k as f64 * DT;
            let y = from as f64 * LANE_WIDTH
                + (to as f64 - from as f64) * LANE_WIDTH * quintic(t, start, LC_DURATION);
            (k, x0 + SPEED * t, y + noise(id, k))
        })
        .collect();
    Vehicle { id, samples }
}

/// Writes a scenario: lanes `0` (right) and `1` (left) of 100 m lanelets from x = -100
/// to `ends[lane]`, linked by successors and adjacency, plus unknown elements the importer
/// must skip.
fn scenario(pose: Pose, ends: [f64; 2], vehicles: &[Vehicle], version: &str) -> String {
    let mut xml = String::new();
    let _ = write!(
        xml,
        r#"<?xml version="1.0" ?>
<commonRoad benchmarkID="TEST_Road-1_1_T-1" commonRoadVersion="{version}" timeStepSize="{DT}" author="test">
  <location><geoNameId>0</geoNameId><gpsLatitude>0</gpsLatitude><gpsLongitude>0</gpsLongitude></location>
  <scenarioTags><highway/><multi_lane/></scenarioTags>
"#
    );
    let id = |lane: usize, seg: usize| (lane * 100 + seg + 1) as i64;
    let segments = |lane: usize| ((ends[lane] + 100.0) / 100.0).round() as usize;
    for lane in 0..2 {
        for seg in 0..segments(lane) {
            let x0 = -100.0 + 100.0 * seg as f64;
            let bound = |y: f64| {
                let mut b = String::new();
                for p in 0..=10 {
                    let (x, y) = pose.apply(x0 + 10.0 * p as f64, y);
                    let _ = write!(b, "<point><x>{x}</x><y>{y}</y></point>");
                }
                b
            };
            let yc = lane as f64 * LANE_WIDTH;
            let _ = write!(
                xml,
                "  <lanelet id=\"{}\"><leftBound>{}<lineMarking>dashed</lineMarking></leftBound><rightBound>{}</rightBound>",
                id(lane, seg),
                bound(yc + LANE_WIDTH / 2.0),
                bound(yc - LANE_WIDTH / 2.0)
            );
            if seg > 0 {
                let _ = write!(xml, "<predecessor ref=\"{}\"/>", id(lane, seg - 1));
            }
            if seg + 1 < segments(lane) {
                let _ = write!(xml, "<successor ref=\"{}\"/>", id(lane, seg + 1));
            }
            let other = 1 - lane;
            if seg < segments(other) {
                let side = if lane == 0 {
                    "adjacentLeft"
                } else {
                    "adjacentRight"
                };
                let _ = write!(
                    xml,
                    "<{side} ref=\"{}\" drivingDir=\"same\"/>",
                    id(other, seg)
                );
            }
            xml.push_str("<laneletType>highway</laneletType></lanelet>\n");
        }
    }
    xml.push_str("  <trafficSign id=\"900\"><trafficSignElement><trafficSignID>274</trafficSignID></trafficSignElement></trafficSign>\n");
    xml.push_str("  <staticObstacle id=\"901\"><type>parkedVehicle</type><shape><rectangle><length>4</length><width>2</width></rectangle></shape></staticObstacle>\n");
    for v in vehicles {
        let _ = write!(
            xml,
            "  <dynamicObstacle id=\"{}\"><type>car</type><shape><rectangle><length>4.5</length><width>1.8</width></rectangle></shape>",
            v.id
        );
        for (n, &(step, x, y)) in v.samples.iter().enumerate() {
            let (x, y) = if x.is_finite() {
                pose.apply(x, y)
            } else {
                (x, y)
            };
            let tag = if n == 0 { "initialState" } else { "state" };
            if n == 1 {
                xml.push_str("<trajectory>");
            }
            let _ = write!(
                xml,
                "<{tag}><position><point><x>{x}</x><y>{y}</y></point></position><orientation><exact>{}</exact></orientation>\
                 <time><exact>{step}</exact></time><velocity><exact>{SPEED}</exact></velocity></{tag}>",
                pose.angle
            );
        }
        if v.samples.len() > 1 {
            xml.push_str("</trajectory>");
        }
        xml.push_str("</dynamicObstacle>\n");
    }
    xml.push_str("  <planningProblem id=\"999\"><initialState><position><point><x>0</x><y>0</y></point></position></initialState></planningProblem>\n</commonRoad>\n");
    xml
}

/// The test bed: keepers in both lanes, the lane change (10), one cut by the end (11), one
/// with a gap (12) and one with a NaN (13).
fn vehicles() -> Vec<Vehicle> {
    let mut gap = keeper(12, -80.0, 0);
    gap.samples.remove(50);
    let mut nan = keeper(13, 300.0, 1);
    nan.samples[30].1 = f64::NAN;
    vec![
        keeper(1, 60.0, 0),
        keeper(2, 80.0, 1),
        keeper(3, -10.0, 1),
        keeper(4, -90.0, 1),
        changer(10, 20.0, 0, 1, LC_START, STEPS),
        changer(11, 100.0, 1, 0, 17.0, STEPS),
        gap,
        nan,
    ]
}

fn import(pose: Pose) -> ScenarioImport {
    let xml = scenario(pose, [600.0, 600.0], &vehicles(), "2020a");
    import_str(&xml, "test.xml").unwrap()
}

#[test]
fn finds_the_lane_change_and_counts_the_rest() {
    let imported = import(Pose::IDENTITY);
    let c = imported.source.counts;
    assert_eq!(c.vehicles, 8);
    assert_eq!(c.skipped_time_gap, 1);
    assert_eq!(c.skipped_non_finite, 1);
    assert_eq!(c.lane_changes, 1, "{c:?}");
    assert_eq!(c.cut_by_recording, 1, "{c:?}");
    assert_eq!(c.merges, 0);
    assert_eq!(c.traffic_centres, 0, "the map's centres are the traffic's");
    let reasons: Vec<_> = imported
        .skipped
        .iter()
        .map(|s| (s.vehicle_id, s.reason, s.time_step))
        .collect();
    assert_eq!(
        reasons,
        [
            (12, SkipReason::TimeGap, Some(51)),
            (13, SkipReason::NonFinite, Some(30))
        ]
    );

    let lc = &imported.lane_changes[0];
    assert_eq!(lc.vehicle_id, 10);
    assert_eq!(lc.direction, Direction::Left);
    assert_eq!(lc.centre_source, CentreSource::Map);
    assert!(!lc.merge);
    let start = lc.start_time_step as f64 * DT;
    let end = lc.end_time_step as f64 * DT;
    assert!((start - LC_START).abs() < 0.7, "start {start}");
    assert!((end - (LC_START + LC_DURATION)).abs() < 0.7, "end {end}");
    assert!((lc.duration_s - (end - start)).abs() < 1e-9);
    assert!(
        (lc.lane_width_m - LANE_WIDTH).abs() < 0.05,
        "width {}",
        lc.lane_width_m
    );
    assert!((lc.speed_at_start_mps - SPEED).abs() < 1e-9);
    let peak = 1.875 * LANE_WIDTH / LC_DURATION;
    assert!(
        (lc.peak_lateral_speed_mps - peak).abs() < 0.1,
        "peak {}",
        lc.peak_lateral_speed_mps
    );
    assert_eq!(
        (lc.first_time_step, lc.last_time_step),
        (0, STEPS as i64 - 1)
    );

    // The trace: a second of margin either side, 0 at the start, the lane width at the end.
    let first = lc.trace.first().unwrap();
    let last = lc.trace.last().unwrap();
    assert!((first.time_s + 1.0).abs() < 1e-9);
    assert!((last.time_s - lc.duration_s - 1.0).abs() < 1e-9);
    assert!(first.lateral_m.abs() < 0.1);
    assert!((last.lateral_m - LANE_WIDTH).abs() < 0.1);
    for s in &lc.trace {
        let truth = LANE_WIDTH * quintic(start + s.time_s, LC_START, LC_DURATION);
        assert!((s.lateral_m - truth).abs() < 0.06, "{s:?} vs {truth}");
    }

    // The start's context: all cars at 25 m/s, 4.5 m long.
    let x_ego = 20.0 + SPEED * start;
    let ahead = lc.context.ahead.unwrap();
    assert_eq!(ahead.vehicle_id, 1);
    assert!((ahead.net_gap_m - 35.5).abs() < 0.1, "{ahead:?}");
    assert!(ahead.closing_speed_mps.abs() < 1e-9);
    assert!((ahead.time_headway_s.unwrap() - 35.5 / SPEED).abs() < 0.01);
    let lead = lc.context.target_lead.unwrap();
    assert_eq!(lead.vehicle_id, 2);
    assert!((lead.net_gap_m - 55.5).abs() < 0.1, "{lead:?}");
    let lag = lc.context.target_lag.unwrap();
    assert_eq!(lag.vehicle_id, 3);
    assert!((lag.net_gap_m - 25.5).abs() < 0.1, "{lag:?} at x {x_ego}");
}

#[test]
fn a_lane_change_out_of_an_ending_lane_is_a_merge() {
    // Lane 0 ends at x = 300 while lane 1 goes on to 600: vehicle 10 merges at x ≈ 300.
    let vehicles = [changer(10, 20.0, 0, 1, LC_START, 140), keeper(2, 0.0, 1)];
    let xml = scenario(Pose::IDENTITY, [300.0, 600.0], &vehicles, "2020a");
    let imported = import_str(&xml, "merge.xml").unwrap();
    assert_eq!(imported.source.counts.lane_changes, 1);
    assert_eq!(imported.source.counts.merges, 1);
    assert!(imported.lane_changes[0].merge);
    assert!(imported.lane_changes[0].context.target_lead.is_none());
    assert!(imported.lane_changes[0].context.ahead.is_none());
}

#[test]
fn a_shifted_lane_centre_is_taken_from_the_traffic() {
    // Everyone drives 0.5 m left of the map's centres.
    let shift = |mut v: Vehicle| {
        for s in &mut v.samples {
            s.2 += 0.5;
        }
        v
    };
    let vehicles: Vec<Vehicle> = [
        keeper(1, 60.0, 0),
        keeper(5, -50.0, 0),
        keeper(2, 80.0, 1),
        changer(10, 20.0, 0, 1, LC_START, STEPS),
    ]
    .into_iter()
    .map(shift)
    .collect();
    let xml = scenario(Pose::IDENTITY, [600.0, 600.0], &vehicles, "2020a");
    let imported = import_str(&xml, "shift.xml").unwrap();
    let lc = &imported.lane_changes[0];
    assert_eq!(lc.centre_source, CentreSource::Traffic);
    assert!(imported.source.counts.traffic_centres > 0);
    assert!(lc.trace[0].lateral_m.abs() < 0.1, "{:?}", lc.trace[0]);
    assert!((lc.lane_width_m - LANE_WIDTH).abs() < 0.1);
}

#[test]
fn a_scenario_without_lane_changes_has_zero_counts() {
    let xml = scenario(
        Pose::IDENTITY,
        [600.0, 600.0],
        &[keeper(1, 0.0, 0), keeper(2, 0.0, 1)],
        "2020a",
    );
    let imported = import_str(&xml, "quiet.xml").unwrap();
    assert_eq!(imported.source.counts.lane_changes, 0);
    assert_eq!(imported.source.counts.crossings, 0);
    assert!(imported.lane_changes.is_empty());
}

fn error(xml: &str) -> ImportError {
    import_str(xml, "bad.xml").unwrap_err()
}

#[test]
fn malformed_xml_is_an_error_with_its_position() {
    let good = scenario(Pose::IDENTITY, [200.0, 200.0], &[], "2020a");
    let bad = good.replacen("</lanelet>", "</lanelett>", 1);
    let e = error(&bad);
    let ImportError::Xml { line, .. } = &e else {
        panic!("{e}")
    };
    assert_eq!(*line, 5, "{e}");
    assert!(e.to_string().starts_with("bad.xml:"), "{e}");
}

#[test]
fn a_non_numeric_coordinate_is_an_error() {
    let good = scenario(Pose::IDENTITY, [200.0, 200.0], &[], "2020a");
    let e = error(&good.replacen("<x>-100</x>", "<x>west</x>", 1));
    assert!(matches!(e, ImportError::Xml { .. }), "{e}");
}

#[test]
fn version_2018b_is_refused_with_the_conversion() {
    let xml = scenario(Pose::IDENTITY, [200.0, 200.0], &[], "2018b");
    let e = error(&xml);
    assert!(
        matches!(&e, ImportError::UnsupportedVersion { version, .. } if version == "2018b"),
        "{e}"
    );
    assert!(e.to_string().contains("CommonRoadFileReader"), "{e}");
    assert!(e.to_string().contains("CommonRoadFileWriter"), "{e}");
}

#[test]
fn another_root_is_refused() {
    let e = error("<?xml version=\"1.0\"?><osm version=\"0.6\"></osm>");
    assert!(
        matches!(&e, ImportError::NotCommonRoad { root, .. } if root == "osm"),
        "{e}"
    );
    assert!(matches!(error(""), ImportError::NotCommonRoad { .. }));
}

#[test]
fn a_bad_time_step_is_refused() {
    let xml = scenario(Pose::IDENTITY, [200.0, 200.0], &[], "2020a")
        .replace("timeStepSize=\"0.1\"", "timeStepSize=\"0\"");
    assert!(matches!(error(&xml), ImportError::InvalidTimeStep { .. }));
}

#[test]
fn a_lanelet_with_one_point_is_refused() {
    let xml = "<commonRoad commonRoadVersion=\"2020a\" benchmarkID=\"X\" timeStepSize=\"0.1\"><lanelet id=\"7\">\
               <leftBound><point><x>0</x><y>1</y></point></leftBound><rightBound><point><x>0</x><y>0</y></point></rightBound></lanelet></commonRoad>";
    let e = error(xml);
    assert!(
        matches!(&e, ImportError::InvalidLanelet { id: 7, .. }),
        "{e}"
    );
}

#[test]
fn a_missing_file_is_an_io_error() {
    let e = import_file(std::path::Path::new("/nonexistent/scenario.xml")).unwrap_err();
    assert!(matches!(e, ImportError::Io { .. }), "{e}");
}

#[test]
fn the_file_round_trips_and_validates() {
    let mut file = RecordedLaneChanges::new();
    file.push(import(Pose::IDENTITY));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lc.json");
    std::fs::write(&path, file.to_json()).unwrap();
    let back = RecordedLaneChanges::read(&path).unwrap();
    assert_eq!(
        (back.counts, &back.sources, &back.skipped_vehicles),
        (file.counts, &file.sources, &file.skipped_vehicles)
    );
    let (a, b) = (&back.lane_changes[0], &file.lane_changes[0]);
    assert_eq!(
        (
            a.vehicle_id,
            a.start_time_step,
            a.end_time_step,
            a.trace.len()
        ),
        (
            b.vehicle_id,
            b.start_time_step,
            b.end_time_step,
            b.trace.len()
        )
    );
    for (p, q) in a.trace.iter().zip(&b.trace) {
        assert!((p.time_s - q.time_s).abs() < 1e-12 && (p.lateral_m - q.lateral_m).abs() < 1e-12);
    }

    let write_and_read = |text: String| {
        std::fs::write(&path, text).unwrap();
        RecordedLaneChanges::read(&path).unwrap_err()
    };
    let json = file.to_json();
    let e = write_and_read(json.replacen("\"palc-recorded-lane-changes\"", "\"other\"", 1));
    assert!(
        matches!(&e, ReadError::Invalid { field, .. } if field == "format"),
        "{e}"
    );
    let e = write_and_read(json.replacen("\"version\": 1", "\"version\": 2", 1));
    assert!(
        matches!(&e, ReadError::Invalid { field, .. } if field == "version"),
        "{e}"
    );
    // A byte-order mark is skipped.
    std::fs::write(&path, format!("\u{feff}{json}")).unwrap();
    assert_eq!(RecordedLaneChanges::read(&path).unwrap(), file);
    // A later version is named as such, not by a field it lacks.
    let e =
        write_and_read("{\"format\": \"palc-recorded-lane-changes\", \"version\": 2}".to_owned());
    assert!(
        matches!(&e, ReadError::Invalid { field, .. } if field == "version"),
        "{e}"
    );
    let e = write_and_read(json.replacen("\"merge\": false", "\"merge\": false, \"extra\": 1", 1));
    assert!(matches!(e, ReadError::Json { .. }), "{e}");

    let mut bad = file.clone();
    bad.lane_changes[0].trace[3].time_s = bad.lane_changes[0].trace[2].time_s;
    let e = bad.validate(&path).unwrap_err();
    assert!(
        e.to_string().contains("lane_changes[0].trace[3].time_s"),
        "{e}"
    );
    let mut bad = file.clone();
    bad.lane_changes[0].lane_width_m = f64::NAN;
    let e = bad.validate(&path).unwrap_err();
    assert!(
        matches!(&e, ReadError::Invalid { field, .. } if field == "lane_changes[0].lane_width_m"),
        "{e}"
    );
    let mut bad = file.clone();
    bad.lane_changes[0].end_time_step = bad.lane_changes[0].start_time_step;
    assert!(bad.validate(&path).is_err());
    assert!(matches!(
        RecordedLaneChanges::read(&dir.path().join("none.json")),
        Err(ReadError::Io { .. })
    ));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    /// Rotating and translating the whole scenario moves nothing that the importer reports.
    #[test]
    fn the_lane_change_is_invariant_under_rigid_motions(
        angle in 0.0..std::f64::consts::TAU,
        tx in -5000.0..5000.0f64,
        ty in -5000.0..5000.0f64,
    ) {
        let reference = import(Pose::IDENTITY);
        let moved = import(Pose { angle, tx, ty });
        prop_assert_eq!(moved.source.counts, reference.source.counts);
        let (a, b) = (&reference.lane_changes[0], &moved.lane_changes[0]);
        prop_assert!((a.start_time_step - b.start_time_step).abs() <= 1);
        prop_assert!((a.end_time_step - b.end_time_step).abs() <= 1);
        prop_assert!((a.lane_width_m - b.lane_width_m).abs() < 1e-3);
        let ahead = (a.context.ahead.unwrap().net_gap_m - b.context.ahead.unwrap().net_gap_m).abs();
        prop_assert!(ahead < 1e-3);
        for (p, q) in a.trace.iter().zip(&b.trace) {
            if (p.time_s - q.time_s).abs() < 1e-9 {
                prop_assert!((p.lateral_m - q.lateral_m).abs() < 1e-3);
            }
        }
    }
}

/// A scenario or recorded file larger than the input bound is refused from its
/// size, naming the file, its size and the bound.
#[test]
fn a_file_past_the_size_bound_is_refused_before_it_is_read() {
    let path = std::env::temp_dir().join(format!("palc-cr-large-{}.xml", std::process::id()));
    let file = std::fs::File::create(&path).unwrap();
    // Sparse: the bound and one byte, without writing them.
    file.set_len(palc_commonroad::import::MAX_FILE_BYTES + 1)
        .unwrap();
    let message = palc_commonroad::import::import_file(&path)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains(&path.display().to_string())
            && message.contains("67108865 bytes")
            && message.contains("67108864 bytes"),
        "{message}"
    );
    let message = palc_commonroad::import::RecordedLaneChanges::read(&path)
        .unwrap_err()
        .to_string();
    assert!(message.contains("67108865 bytes"), "{message}");
    std::fs::remove_file(&path).unwrap();
}
