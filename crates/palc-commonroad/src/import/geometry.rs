//! Plane geometry of lanelets: centre polylines, projection of a point onto a polyline
//! (arc length and signed lateral offset, positive to the left) and point-in-polygon.

use super::params::POINT_MERGE_M;

/// A point in the scenario's plane (m).
pub(crate) type Point = [f64; 2];

/// A polyline with its cumulative arc length.
#[derive(Debug, Clone)]
pub(crate) struct Polyline {
    points: Vec<Point>,
    arc: Vec<f64>,
}

/// A point's position relative to a polyline.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Projection {
    /// Arc length of the foot point (m); below 0 or beyond the length when the point lies
    /// before the first or after the last segment.
    pub s: f64,
    /// Signed distance from the polyline, positive to its left (m).
    pub d: f64,
}

impl Polyline {
    /// A polyline through `points`, with points closer than [`POINT_MERGE_M`] merged;
    /// `None` with fewer than two distinct points.
    pub fn new(points: impl IntoIterator<Item = Point>) -> Option<Self> {
        let mut kept: Vec<Point> = Vec::new();
        for p in points {
            if kept.last().is_none_or(|q| dist(*q, p) > POINT_MERGE_M) {
                kept.push(p);
            }
        }
        if kept.len() < 2 {
            return None;
        }
        let mut arc = Vec::with_capacity(kept.len());
        let mut s = 0.0;
        arc.push(0.0);
        for w in kept.windows(2) {
            s += dist(w[0], w[1]);
            arc.push(s);
        }
        Some(Self { points: kept, arc })
    }

    /// The points.
    pub fn points(&self) -> &[Point] {
        &self.points
    }

    /// The total length (m).
    pub fn length(&self) -> f64 {
        self.arc.last().copied().unwrap_or(0.0)
    }

    /// Projects `p` onto the nearest segment; the first and last segments are extended
    /// beyond the ends.
    pub fn project(&self, p: Point) -> Projection {
        let last = self.points.len() - 2;
        let mut best = (f64::INFINITY, Projection { s: 0.0, d: 0.0 });
        for i in 0..=last {
            let (a, b) = (self.points[i], self.points[i + 1]);
            let seg = [b[0] - a[0], b[1] - a[1]];
            let len = (seg[0] * seg[0] + seg[1] * seg[1]).sqrt();
            let rel = [p[0] - a[0], p[1] - a[1]];
            let t = (rel[0] * seg[0] + rel[1] * seg[1]) / (len * len);
            let clamped = t.clamp(0.0, 1.0);
            let foot = [a[0] + clamped * seg[0], a[1] + clamped * seg[1]];
            let distance = dist(foot, p);
            if distance < best.0 {
                let t = if (i == 0 && t < 0.0) || (i == last && t > 1.0) {
                    t
                } else {
                    clamped
                };
                let d = (seg[0] * rel[1] - seg[1] * rel[0]) / len;
                best = (
                    distance,
                    Projection {
                        s: self.arc[i] + t * len,
                        d,
                    },
                );
            }
        }
        best.1
    }
}

/// Euclidean distance.
pub(crate) fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Resamples a polyline (given by its points) to `n` points evenly spaced in arc length.
pub(crate) fn resample(points: &[Point], n: usize) -> Vec<Point> {
    let Some(line) = Polyline::new(points.iter().copied()) else {
        return points.to_vec();
    };
    let total = line.length();
    (0..n)
        .map(|k| {
            let target = total * k as f64 / (n.max(2) - 1) as f64;
            let i = line
                .arc
                .partition_point(|&s| s <= target)
                .clamp(1, line.arc.len() - 1);
            let (s0, s1) = (line.arc[i - 1], line.arc[i]);
            let t = if s1 > s0 {
                (target - s0) / (s1 - s0)
            } else {
                0.0
            };
            let (a, b) = (line.points[i - 1], line.points[i]);
            [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
        })
        .collect()
}

/// Whether `p` lies inside the polygon `ring` (even-odd rule; the ring is closed
/// implicitly).
pub(crate) fn contains(ring: &[Point], p: Point) -> bool {
    let mut inside = false;
    let mut j = ring.len().wrapping_sub(1);
    for i in 0..ring.len() {
        let (a, b) = (ring[i], ring[j]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}
