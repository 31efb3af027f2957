//! Finding the lane changes of a scenario's tracks and describing each one.
//!
//! 1. Every sample is put in the lanelet whose polygon contains it ([`Map::locate`]).
//! 2. A change of lanelet from `A` to `B` between consecutive located samples is a
//!    *crossing* when `B`'s chain is laterally adjacent to `A`'s in the same driving
//!    direction; a change along successors or predecessors is not, and any other change is
//!    counted as unlinked.
//! 3. For a crossing, the lateral position `y` of every sample is measured from `A`'s
//!    corridor, positive towards `B`, and the lateral speed is the slope of a least-squares
//!    line over ±[`LATERAL_SPEED_HALF_WINDOW_S`] (truncated at the track's ends). The lane
//!    change is the maximal run of samples around the crossing (the fastest of the two
//!    samples either side of it) where that speed exceeds [`LATERAL_SPEED_THRESHOLD_MPS`]:
//!    its first sample is the start, its last the end. A run that reaches the track's first
//!    or last sample is *cut by the recording* and skipped; a crossing whose speed never
//!    exceeds the threshold is *slow* and skipped; a crossing inside a run already found
//!    for the same vehicle is *repeated* and skipped.
//! 4. Lane centres: for each lanelet, the median lateral offset from its map centre of the
//!    samples it contains, leaving out samples within [`CENTRE_EXCLUSION_S`] of any crossing
//!    of their vehicle. With at least [`CENTRE_MIN_SAMPLES`] and a median beyond
//!    [`CENTRE_TOLERANCE_M`], the traffic's centre replaces the map's for every measure of
//!    the lane changes that start in that lanelet (the offset is constant along the
//!    corridor, so the start and end found in step 3 do not depend on it).

use super::error::ImportError;
use super::geometry::Projection;
use super::map::Map;
use super::params::{
    CENTRE_EXCLUSION_S, CENTRE_MIN_SAMPLES, CENTRE_TOLERANCE_M, HEADWAY_MIN_SPEED_MPS,
    LATERAL_SPEED_HALF_WINDOW_S, LATERAL_SPEED_MIN_SAMPLES, LATERAL_SPEED_THRESHOLD_MPS,
    MERGE_MARGIN_M, TRACE_MARGIN_S,
};
use super::record::{
    CentreSource, Counts, Direction, LateralSample, Neighbour, RecordedLaneChange, StartContext,
};
use super::tracks::Track;

/// A lane change found in step 3, before it is described.
#[derive(Debug)]
struct Candidate {
    track: usize,
    from: usize,
    to: usize,
    direction: Direction,
    crossing: usize,
    start: usize,
    end: usize,
}

/// `x` rounded to a multiple of `unit` (the file's resolution: 0.1 mm, 1e-4 m/s, 1 µs), so that a trace's times are the step's multiples, not `0.30000000000000004`.
fn round(x: f64, unit: f64) -> f64 {
    let r = (x / unit).round() * unit;
    // Printing through a decimal string gives the double nearest to the rounded decimal.
    format!("{r:.10}").parse().unwrap_or(r)
}

/// The sign that turns a left-positive offset into one positive towards the target.
fn sign(direction: Direction) -> f64 {
    match direction {
        Direction::Left => 1.0,
        Direction::Right => -1.0,
    }
}

/// Slope of the least-squares line through `y` over a centred window of `half` samples on
/// each side (truncated at the ends), divided by `dt`; NaN with fewer than
/// [`LATERAL_SPEED_MIN_SAMPLES`] samples in the window.
pub(crate) fn lateral_speed(y: &[f64], dt: f64, half: usize) -> Vec<f64> {
    (0..y.len())
        .map(|i| {
            let (a, b) = (
                i.saturating_sub(half),
                i.saturating_add(half).min(y.len() - 1),
            );
            let count = b - a + 1;
            if count < LATERAL_SPEED_MIN_SAMPLES {
                return f64::NAN;
            }
            let mean_k = (a + b) as f64 / 2.0;
            let mean_y = y[a..=b].iter().sum::<f64>() / count as f64;
            let (mut num, mut den) = (0.0, 0.0);
            for k in a..=b {
                let dk = k as f64 - mean_k;
                num += dk * (y[k] - mean_y);
                den += dk * dk;
            }
            num / den / dt
        })
        .collect()
}

/// The lane changes of a scenario, with the counts of what was skipped.
///
/// # Errors
/// [`ImportError::InvalidLanelet`] when two lanelets a vehicle changes between
/// have centres (the map's, or the traffic's on them) that are not a positive
/// lane width apart on the side of the lane change (`file` names the source).
pub(crate) fn lane_changes(
    map: &Map,
    tracks: &[Track],
    dt: f64,
    (file, scenario): (&str, &str),
    counts: &mut Counts,
) -> Result<Vec<RecordedLaneChange>, ImportError> {
    let half = (LATERAL_SPEED_HALF_WINDOW_S / dt).round().max(1.0) as usize;
    let exclusion = (CENTRE_EXCLUSION_S / dt).round() as usize;
    let located: Vec<Vec<Option<usize>>> = tracks
        .iter()
        .map(|t| t.position.iter().map(|&p| map.locate(p)).collect())
        .collect();
    let mut candidates = Vec::new();
    let mut excluded: Vec<Vec<bool>> = tracks.iter().map(|t| vec![false; t.len()]).collect();
    for (ti, track) in tracks.iter().enumerate() {
        let n = track.len();
        let mut runs: Vec<(usize, usize)> = Vec::new();
        let mut last: Option<(usize, usize)> = None;
        for i in 0..n {
            let Some(b) = located[ti][i] else { continue };
            let Some((j, a)) = last.replace((i, b)) else {
                continue;
            };
            if a == b || map.longitudinal(a, b) {
                continue;
            }
            let Some(direction) = map.lateral(a, b) else {
                counts.unlinked_transitions += 1;
                continue;
            };
            counts.crossings += 1;
            let corridor = map.corridor(a);
            let y: Vec<f64> = track
                .position
                .iter()
                .map(|&p| sign(direction) * corridor.project(p).d)
                .collect();
            let v = lateral_speed(&y, dt, half);
            let crossing = (j..=i)
                .filter(|&k| v[k].is_finite())
                .max_by(|&p, &q| v[p].total_cmp(&v[q]));
            let mark = |from: usize, to: usize, excluded: &mut Vec<bool>| {
                for e in &mut excluded[from.min(n)..=to.min(n - 1)] {
                    *e = true;
                }
            };
            mark(
                j.saturating_sub(exclusion),
                i.saturating_add(exclusion),
                &mut excluded[ti],
            );
            let Some(crossing) = crossing.filter(|&k| v[k] > LATERAL_SPEED_THRESHOLD_MPS) else {
                counts.slow_crossings += 1;
                continue;
            };
            if runs.iter().any(|&(s, e)| s <= crossing && crossing <= e) {
                counts.repeated_crossings += 1;
                continue;
            }
            let mut start = crossing;
            while start > 0 && v[start - 1] > LATERAL_SPEED_THRESHOLD_MPS {
                start -= 1;
            }
            let mut end = crossing;
            while end + 1 < n && v[end + 1] > LATERAL_SPEED_THRESHOLD_MPS {
                end += 1;
            }
            runs.push((start, end));
            mark(start, end, &mut excluded[ti]);
            if start == 0 || end == n - 1 {
                counts.cut_by_recording += 1;
                continue;
            }
            candidates.push(Candidate {
                track: ti,
                from: a,
                to: b,
                direction,
                crossing: i,
                start,
                end,
            });
        }
    }
    let offsets = traffic_centres(map, tracks, &located, &excluded, counts);
    candidates
        .iter()
        .map(|c| describe(map, tracks, &offsets, c, dt, half, (file, scenario), counts))
        .collect()
}

/// Each lanelet's centre offset from the map's (left-positive, m), `None` where the map's
/// centre is kept.
fn traffic_centres(
    map: &Map,
    tracks: &[Track],
    located: &[Vec<Option<usize>>],
    excluded: &[Vec<bool>],
    counts: &mut Counts,
) -> Vec<Option<f64>> {
    let mut offsets: Vec<Vec<f64>> = vec![Vec::new(); map.lanelets.len()];
    for (ti, track) in tracks.iter().enumerate() {
        for (k, &p) in track.position.iter().enumerate() {
            if let (Some(l), false) = (located[ti][k], excluded[ti][k]) {
                offsets[l].push(map.lanelets[l].centre.project(p).d);
            }
        }
    }
    offsets
        .into_iter()
        .map(|mut d| {
            if d.len() < CENTRE_MIN_SAMPLES {
                return None;
            }
            d.sort_by(f64::total_cmp);
            let m = d.len() / 2;
            let median = if d.len() % 2 == 0 {
                (d[m - 1] + d[m]) / 2.0
            } else {
                d[m]
            };
            (median.abs() > CENTRE_TOLERANCE_M).then(|| {
                counts.traffic_centres += 1;
                median
            })
        })
        .collect()
}

/// The record of one candidate.
fn describe(
    map: &Map,
    tracks: &[Track],
    offsets: &[Option<f64>],
    c: &Candidate,
    dt: f64,
    half: usize,
    (file, scenario): (&str, &str),
    counts: &mut Counts,
) -> Result<RecordedLaneChange, ImportError> {
    let track = &tracks[c.track];
    let n = track.len();
    let sg = sign(c.direction);
    let corridor = map.corridor(c.from);
    let offset_from = offsets[c.from].unwrap_or(0.0);
    let offset_to = offsets[c.to].unwrap_or(0.0);
    let frenet = |p| {
        let Projection { s, d } = corridor.project(p);
        (s, sg * (d - offset_from))
    };
    let y: Vec<f64> = track.position.iter().map(|&p| frenet(p).1).collect();
    let v = lateral_speed(&y, dt, half);
    let peak = v[c.start..=c.end]
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let p = track.position[c.crossing];
    let width = y[c.crossing] - sg * (map.corridor(c.to).project(p).d - offset_to);
    if !(width.is_finite() && width > 0.0) {
        return Err(ImportError::InvalidLanelet {
            source_name: file.to_owned(),
            id: map.lanelets[c.to].id,
            reason: format!(
                "vehicle {} changes into it from lanelet {} at step {}, where the two centres lie {width:?} m apart \
                 on the side of the lane change (must be positive and finite): the lanelets overlap or lie in the wrong order",
                track.id,
                map.lanelets[c.from].id,
                track.first_step + c.crossing as i64,
            ),
        });
    }
    let end_on_target = map.corridor(c.to).project(map.corridor_end(c.from)).s;
    let merge = map.corridor(c.to).length() - end_on_target > MERGE_MARGIN_M;
    if merge {
        counts.merges += 1;
    }
    counts.lane_changes += 1;
    let margin = (TRACE_MARGIN_S / dt).round() as usize;
    let trace = (c.start.saturating_sub(margin)..=c.end.saturating_add(margin).min(n - 1))
        .map(|k| LateralSample {
            time_s: round((k as f64 - c.start as f64) * dt, 1e-6),
            lateral_m: round(y[k], 1e-4),
        })
        .collect();
    let start_step = track.first_step + c.start as i64;
    let s_ego = frenet(track.position[c.start]).0;
    let v_ego = track.speed[c.start];
    let mut context = StartContext {
        ahead: None,
        target_lead: None,
        target_lag: None,
    };
    let neighbour = |other: &Track, ds: f64, closing: f64| {
        let net_gap_m = ds.abs() - (track.length + other.length) / 2.0;
        Neighbour {
            vehicle_id: other.id,
            net_gap_m: round(net_gap_m, 1e-4),
            closing_speed_mps: round(closing, 1e-4),
            time_headway_s: (v_ego >= HEADWAY_MIN_SPEED_MPS)
                .then(|| round(net_gap_m / v_ego, 1e-4)),
        }
    };
    let closer = |current: &Option<Neighbour>, candidate: &Neighbour| {
        current.is_none_or(|n| candidate.net_gap_m < n.net_gap_m)
    };
    for (oi, other) in tracks.iter().enumerate() {
        let Some(k) = other.index_of(start_step).filter(|_| oi != c.track) else {
            continue;
        };
        let (s, y_other) = frenet(other.position[k]);
        if s < 0.0 || s > corridor.length() {
            continue;
        }
        let ds = s - s_ego;
        let v_other = other.speed[k];
        if y_other.abs() < width / 2.0 && ds > 0.0 {
            let n = neighbour(other, ds, v_ego - v_other);
            if closer(&context.ahead, &n) {
                context.ahead = Some(n);
            }
        } else if (y_other - width).abs() < width / 2.0 {
            if ds >= 0.0 {
                let n = neighbour(other, ds, v_ego - v_other);
                if closer(&context.target_lead, &n) {
                    context.target_lead = Some(n);
                }
            } else {
                let n = neighbour(other, ds, v_other - v_ego);
                if closer(&context.target_lag, &n) {
                    context.target_lag = Some(n);
                }
            }
        }
    }
    Ok(RecordedLaneChange {
        scenario: scenario.to_owned(),
        vehicle_id: track.id,
        vehicle_type: track.kind.clone(),
        vehicle_length_m: track.length,
        vehicle_width_m: track.width,
        dt_s: dt,
        first_time_step: track.first_step,
        last_time_step: track.last_step(),
        start_time_step: start_step,
        end_time_step: track.first_step + c.end as i64,
        direction: c.direction,
        start_lanelet: map.lanelets[c.from].id,
        target_lanelet: map.lanelets[c.to].id,
        duration_s: round((c.end - c.start) as f64 * dt, 1e-6),
        peak_lateral_speed_mps: round(peak, 1e-4),
        speed_at_start_mps: round(v_ego, 1e-4),
        lane_width_m: round(width, 1e-4),
        context,
        merge,
        centre_source: if offsets[c.from].is_some() {
            CentreSource::Traffic
        } else {
            CentreSource::Map
        },
        trace,
    })
}
