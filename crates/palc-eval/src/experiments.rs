//! The figures of Section III drawn from the runs (Figs. 6-13).

use std::path::Path;

use palc_harness::{Method, record::Timings};

use crate::EvalError;
use crate::figures::{self, Bars, Example, Lines};
use crate::harness_runs::ExampleTrace;
use crate::plan::Experiment;
use crate::results::RunRow;
use crate::scenes::{Axis, accumulation_places, matrix_pairs};
use crate::stats;
use crate::views::{FigureFile, grid, slug, speed_label, timing, with_transfer};

/// Series of a bar chart: name and one value per category.
type BarSeries = Vec<(String, Vec<Option<f64>>)>;

/// How rows are grouped into categories.
type Key<'a> = &'a dyn Fn(&RunRow) -> String;

fn means_by(
    rows: &[RunRow],
    methods: &[Method],
    user: &str,
    key: &dyn Fn(&RunRow) -> String,
) -> (Vec<String>, BarSeries) {
    let all: Vec<&RunRow> = methods.iter().flat_map(|&m| grid(rows, m, user)).collect();
    let categories: Vec<String> = stats::by(&all, key).into_iter().map(|(k, _)| k).collect();
    let series = methods
        .iter()
        .map(|method| {
            let groups = stats::by(&grid(rows, *method, user), key);
            let values = (categories.iter())
                .map(|c| {
                    groups
                        .iter()
                        .find(|(k, _)| k == c)
                        .and_then(|(_, s)| s.mean)
                })
                .collect();
            (method.name().to_owned(), values)
        })
        .collect();
    (categories, series)
}

/// The empirical distribution function of `values` as points `(value, fraction at or
/// below)`, thinned to at most 200 points.
fn empirical_cdf(mut values: Vec<f64>) -> Vec<(f64, f64)> {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    let stride = n.div_ceil(200).max(1);
    (0..n)
        .filter(|i| i % stride == 0 || i + 1 == n)
        .map(|i| (values[i], (i + 1) as f64 / n as f64))
        .collect()
}

/// Draws every figure into `dir`.
pub fn draw_all(
    rows: &[RunRow],
    methods: &[Method],
    users: &[String],
    example: Option<&ExampleTrace>,
    dir: &Path,
) -> Result<Vec<FigureFile>, EvalError> {
    figures::register_bundled_font()?;
    let mut files = Vec::new();
    let mut save =
        |stem: String, caption: String, figure: &dyn Fn(&Path, &str) -> Result<(), EvalError>| {
            figure(dir, &stem)?;
            files.push(FigureFile { stem, caption });
            Ok::<(), EvalError>(())
        };
    if let Some(trace) = example {
        save(
            "fig06-example".into(),
            format!("Fig. 6: qualitative example, {}", trace.label),
            &|dir, stem| figures::save(dir, stem, (1400, 560), &Example { trace }).map(|_| ()),
        )?;
    }
    for user in users {
        let tag = slug(user);
        let cap = rows.iter().map(|r| r.cap).max().unwrap_or(30);
        let categories: Vec<String> = (0..=cap).map(|n| n.to_string()).collect();
        let series: BarSeries = methods
            .iter()
            .map(|method| {
                let mut counts = vec![0usize; cap + 1];
                for row in grid(rows, *method, user)
                    .iter()
                    .filter(|r| r.status.counted())
                {
                    counts[row.counted_takeovers().min(cap)] += 1;
                }
                let counts = counts.into_iter().map(|c| Some(c as f64)).collect();
                (method.name().to_owned(), counts)
            })
            .collect();
        let histogram = Bars {
            title: format!("Takeovers to personalization ({user} users; {cap} = failed)"),
            x_desc: "takeovers to personalization".into(),
            y_desc: "runs (count)".into(),
            categories,
            series,
            label_every: 5,
        };
        save(
            format!("fig07-takeovers-{tag}"),
            format!(
                "Fig. 7: distribution of takeovers to personalization, {user} users (a failure is counted at the cap)"
            ),
            &|dir, stem| figures::save(dir, stem, (900, 450), &histogram).map(|_| ()),
        )?;
        let sensitivity: [(&str, &str, &str, Key); 3] = [
            (
                "fig08-style",
                "Fig. 8: mean takeovers by driving style",
                "style",
                &|r| r.spec.style_name().to_owned(),
            ),
            (
                "fig09-speed",
                "Fig. 9: mean takeovers by speed case (ego/others)",
                "speed case",
                &speed_label,
            ),
            (
                "fig10-congestion",
                "Fig. 10: mean takeovers by adjacent headway (congestion)",
                "adjacent headway (m)",
                &|r| format!("{}", r.spec.headway_m),
            ),
        ];
        for (stem, caption, x_desc, key) in sensitivity {
            let (categories, series) = means_by(rows, methods, user, key);
            let figure = Bars {
                title: format!("{caption} ({user})"),
                x_desc: x_desc.into(),
                y_desc: "mean takeovers (failures at the cap)".into(),
                categories,
                series,
                label_every: 1,
            };
            save(
                format!("{stem}-{tag}"),
                format!("{caption}, {user} users"),
                &|dir, stem| figures::save(dir, stem, (900, 450), &figure).map(|_| ()),
            )?;
        }
        let transfers: Vec<(String, stats::Transfer)> = methods
            .iter()
            .map(|&m| {
                (
                    m.name().to_owned(),
                    stats::transfer(&with_transfer(rows, m, user)),
                )
            })
            .filter(|(_, t)| t.pairs > 0)
            .collect();
        if !transfers.is_empty() {
            let figure = Bars {
                title: format!("Experience accumulation ({user})"),
                x_desc: "start of the run".into(),
                y_desc: "mean takeovers over the same cells".into(),
                categories: vec!["without experience".into(), "with experience".into()],
                series: transfers
                    .iter()
                    .map(|(m, t)| (m.clone(), vec![t.without, t.with]))
                    .collect(),
                label_every: 1,
            };
            save(
                format!("fig11-experience-{tag}"),
                format!(
                    "Fig. 11: mean takeovers with and without experience from another scenario, {user} users"
                ),
                &|dir, stem| figures::save(dir, stem, (700, 450), &figure).map(|_| ()),
            )?;
        }
        let safety = Lines {
            title: format!("Perceived safety distance ratio ({user})"),
            x_desc: "lane change (index in the run)".into(),
            y_desc: "perceived safety ratio, mean (-)".into(),
            series: methods
                .iter()
                .map(|&m| {
                    let s = stats::safety(&grid(rows, m, user));
                    let points = (s.mean_by_iteration.iter().enumerate())
                        .map(|(i, &(mean, _))| ((i + 1) as f64, mean))
                        .collect();
                    (m.name().to_owned(), points)
                })
                .collect(),
            y_range: Some((0.0, 1.05)),
            log_y: false,
        };
        save(
            format!("fig12-safety-{tag}"),
            format!(
                "Fig. 12: perceived safety distance ratio against the lane change, {user} users (mean over the runs that drove it)"
            ),
            &|dir, stem| figures::save(dir, stem, (900, 450), &safety).map(|_| ()),
        )?;
    }
    for &method in methods {
        if let Some(figure) = across_scenes(rows, method) {
            let name = method.name();
            save(
                format!("fig15-transfer-{name}"),
                format!(
                    "Fig. 15 (not in the paper): `{name}`, mean takeovers from scratch and with experience from another scene: the transfer matrix's pairs by axis, and accumulation (from scratch: scene 1; with experience: the scenes after it; every user kind) (REPORT.md, \"Experience across scenes\")"
                ),
                &|dir, stem| figures::save(dir, stem, (900, 450), &figure).map(|_| ()),
            )?;
        }
    }
    for &method in methods {
        let drive = crate::drive_report::figures(rows, method, 6);
        let count = drive.len();
        for (i, figure) in drive.iter().enumerate() {
            let name = method.name();
            let part = if count > 1 {
                format!("-{}", i + 1)
            } else {
                String::new()
            };
            save(
                format!("fig16-drive-{name}{part}"),
                format!(
                    "Fig. 16 (not in the paper): `{name}`, takeover rate over the last 10 lane changes of a drive of varied scenes, every style of each user kind together (REPORT.md, \"A drive of varied scenes\")"
                ),
                &|dir, stem| figures::save(dir, stem, (900, 450), figure).map(|_| ()),
            )?;
        }
    }
    let gaps = Lines {
        title: "Smallest net gap per lane change, system-driven steps (grid)".into(),
        x_desc: "smallest net gap to the preceding, lead or lag vehicle (m; < 0: overlap)".into(),
        y_desc: "fraction of lane changes at or below (-)".into(),
        series: methods
            .iter()
            .map(|&m| {
                let values = rows
                    .iter()
                    .filter(|r| r.spec.experiment == Experiment::Grid && r.spec.method == m)
                    .flat_map(|r| &r.iterations)
                    .filter_map(|i| i.safety.min_gap_m());
                (m.name().to_owned(), empirical_cdf(values.collect()))
            })
            .filter(|(_, points)| !points.is_empty())
            .collect(),
        y_range: Some((0.0, 1.05)),
        log_y: false,
    };
    if !gaps.series.is_empty() {
        save(
            "fig14-safety-gaps".into(),
            "Fig. 14 (not in the paper): distribution of the smallest net gap of each grid lane change to the preceding vehicle and the target lane's lead and lag, over the steps the system drove; a gap below 0 is a collision (REPORT.md, safety section)".into(),
            &|dir, stem| figures::save(dir, stem, (900, 450), &gaps).map(|_| ()),
        )?;
    }
    let mut series = Vec::new();
    for &method in methods {
        let timed = timing(rows, method);
        let mut dts: Vec<f64> = timed.iter().filter_map(|r| r.dt).collect();
        dts.sort_by(f64::total_cmp);
        dts.dedup();
        for dt in dts {
            let mut points: Vec<(f64, f64)> = Vec::new();
            let mut horizons: Vec<usize> = timed
                .iter()
                .filter(|r| r.dt == Some(dt))
                .map(|r| r.horizon)
                .collect();
            horizons.sort_unstable();
            horizons.dedup();
            for k in horizons {
                let group = timed
                    .iter()
                    .copied()
                    .filter(|r| r.dt == Some(dt) && r.horizon == k);
                if let Some(t) = stats::timing(group) {
                    points.push((k as f64, t.p95 * 1e3));
                }
            }
            if !points.is_empty() {
                series.push((format!("{}, dt {dt} s", method.name()), points));
            }
        }
    }
    if !series.is_empty() {
        let figure = Lines {
            title: "Compute time per iteration, p95".into(),
            x_desc: "horizon K (steps)".into(),
            y_desc: "time per iteration, p95 (ms, log scale)".into(),
            series,
            y_range: None,
            log_y: true,
        };
        save(
            "fig13-compute".into(),
            "Fig. 13: compute time per iteration (95th percentile) against the horizon K, by method and step".into(),
            &|dir, stem| figures::save(dir, stem, (900, 450), &figure).map(|_| ()),
        )?;
        let parts = Bars {
            title: "Compute time per iteration by part (mean)".into(),
            x_desc: "part of the iteration".into(),
            y_desc: "mean time per iteration (ms)".into(),
            categories: Timings::PART_NAMES.iter().map(|s| s.to_string()).collect(),
            series: methods
                .iter()
                .filter_map(|&m| {
                    let t = stats::timing(timing(rows, m))?;
                    Some((
                        m.name().to_owned(),
                        t.part_means.parts().iter().map(|v| Some(v * 1e3)).collect(),
                    ))
                })
                .collect(),
            label_every: 1,
        };
        save(
            "fig13-parts".into(),
            "Fig. 13 (parts): mean compute time per iteration by part, over the timing runs".into(),
            &|dir, stem| figures::save(dir, stem, (900, 450), &parts).map(|_| ()),
        )?;
    }
    Ok(files)
}

/// Fig. 15: `method`'s transfer matrix pooled by axis, and its accumulation
/// chains pooled over user kinds (scene 1 against the scenes after it); `None`
/// without matrix or accumulation runs.
fn across_scenes(rows: &[RunRow], method: Method) -> Option<Bars> {
    let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    let mut categories = Vec::new();
    let (mut scratch, mut with) = (Vec::new(), Vec::new());
    for axis in Axis::BOTH {
        let pairs = matrix_pairs(rows, method, axis);
        if pairs.is_empty() {
            continue;
        }
        categories.push(format!("from another {}", axis.name()));
        scratch.push(mean(&pairs.iter().map(|p| p.without).collect::<Vec<_>>()));
        with.push(mean(&pairs.iter().map(|p| p.with).collect::<Vec<_>>()));
    }
    for axis in Axis::BOTH {
        let kinds = accumulation_places(rows, method, axis);
        let first: Vec<f64> = kinds
            .iter()
            .flat_map(|(_, p)| p[0].iter().copied())
            .collect();
        let after: Vec<f64> = (kinds.iter())
            .flat_map(|(_, p)| p.iter().skip(1).flatten().copied())
            .collect();
        if after.is_empty() {
            continue;
        }
        categories.push(format!("through the {}s", axis.name()));
        scratch.push(mean(&first));
        with.push(mean(&after));
    }
    (!categories.is_empty()).then(|| Bars {
        title: format!("Experience across scenes ({})", method.name()),
        x_desc: "transfer matrix pairs, accumulation chains".into(),
        y_desc: "mean takeovers (failures at the cap)".into(),
        categories,
        series: vec![
            ("from scratch".into(), scratch),
            ("with experience".into(), with),
        ],
        label_every: 1,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_empirical_cdf_rises_to_one_in_sorted_order() {
        assert!(empirical_cdf(Vec::new()).is_empty());
        let points = empirical_cdf(vec![3.0, -1.0, 2.0, 2.0]);
        assert_eq!(
            points,
            vec![(-1.0, 0.25), (2.0, 0.5), (2.0, 0.75), (3.0, 1.0)]
        );
        let many = empirical_cdf((0..1000).map(f64::from).collect());
        assert!(many.len() <= 201);
        assert_eq!(many.last(), Some(&(999.0, 1.0)));
        assert!(many.windows(2).all(|w| w[0].0 <= w[1].0 && w[0].1 < w[1].1));
    }
}
