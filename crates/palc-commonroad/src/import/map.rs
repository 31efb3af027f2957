//! The road map: lanelets as polygons with centre polylines, their longitudinal links
//! (successors, predecessors) and lateral links (adjacent lanelets driven in the same
//! direction), and each lanelet's corridor (its centre continued along its predecessors
//! and successors).
//!
//! Where a lanelet has several successors (or predecessors) the corridor follows the first
//! one listed in the file; references to lanelets that are not in the map are ignored, so a
//! lane leaves the map where its chain of successors does.

use std::collections::HashMap;

use super::error::ImportError;
use super::geometry::{Point, Polyline, contains, resample};
use super::params::MAX_COORDINATE_M;
use super::record::Direction;
use super::xml::XmlLanelet;

/// One lanelet, ready for geometric queries.
#[derive(Debug)]
pub(crate) struct Lanelet {
    /// The id in the file.
    pub id: i64,
    /// The centre polyline (midpoints of the bounds).
    pub centre: Polyline,
    ring: Vec<Point>,
    bbox: [f64; 4],
    successors: Vec<usize>,
    predecessors: Vec<usize>,
    adjacent_left: Option<usize>,
    adjacent_right: Option<usize>,
}

/// The lanelets of a scenario, indexed from 0 in file order.
#[derive(Debug)]
pub(crate) struct Map {
    /// The lanelets.
    pub lanelets: Vec<Lanelet>,
    /// Each lanelet's chain: itself, all successors of successors and all predecessors
    /// of predecessors.
    chains: Vec<Vec<usize>>,
    /// Each lanelet's corridor.
    corridors: Vec<Polyline>,
}

impl Map {
    /// Builds the map from the file's lanelets.
    pub fn new(xml: &[XmlLanelet], source: &str) -> Result<Self, ImportError> {
        let invalid = |id: i64, reason: &str| ImportError::InvalidLanelet {
            source_name: source.to_owned(),
            id,
            reason: reason.to_owned(),
        };
        let mut index = HashMap::new();
        for (i, l) in xml.iter().enumerate() {
            if index.insert(l.id, i).is_some() {
                return Err(invalid(l.id, "the id appears twice"));
            }
        }
        let mut lanelets = Vec::with_capacity(xml.len());
        for l in xml {
            let left: Vec<Point> = l.left.point.iter().map(|p| [p.x, p.y]).collect();
            let right: Vec<Point> = l.right.point.iter().map(|p| [p.x, p.y]).collect();
            if left.len() < 2 || right.len() < 2 {
                return Err(invalid(l.id, "a bound has fewer than two points"));
            }
            let in_range = |c: &f64| c.is_finite() && c.abs() <= MAX_COORDINATE_M;
            if !left.iter().chain(&right).flatten().all(in_range) {
                return Err(invalid(
                    l.id,
                    "a bound has a coordinate that is not finite or beyond ±1e9 m",
                ));
            }
            let n = left.len().max(right.len());
            let (left, right) = if left.len() == right.len() {
                (left, right)
            } else {
                (resample(&left, n), resample(&right, n))
            };
            let centre = Polyline::new(
                left.iter()
                    .zip(&right)
                    .map(|(a, b)| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0]),
            )
            .ok_or_else(|| invalid(l.id, "the centre line has zero length"))?;
            let ring: Vec<Point> = left.iter().chain(right.iter().rev()).copied().collect();
            let mut bbox = [
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ];
            for p in &ring {
                bbox = [
                    bbox[0].min(p[0]),
                    bbox[1].min(p[1]),
                    bbox[2].max(p[0]),
                    bbox[3].max(p[1]),
                ];
            }
            let refs = |r: &[super::xml::XmlRef]| -> Vec<usize> {
                r.iter().filter_map(|r| index.get(&r.id).copied()).collect()
            };
            let same_dir = |a: &Option<super::xml::XmlAdjacent>| {
                a.as_ref()
                    .filter(|a| a.driving_dir == "same")
                    .and_then(|a| index.get(&a.id).copied())
            };
            lanelets.push(Lanelet {
                id: l.id,
                centre,
                ring,
                bbox,
                successors: refs(&l.successor),
                predecessors: refs(&l.predecessor),
                adjacent_left: same_dir(&l.adjacent_left),
                adjacent_right: same_dir(&l.adjacent_right),
            });
        }
        let chains = (0..lanelets.len())
            .map(|a| {
                let mut chain = vec![a];
                for forward in [true, false] {
                    let mut stack = vec![a];
                    while let Some(x) = stack.pop() {
                        let next = if forward {
                            &lanelets[x].successors
                        } else {
                            &lanelets[x].predecessors
                        };
                        for &y in next {
                            if !chain.contains(&y) {
                                chain.push(y);
                                stack.push(y);
                            }
                        }
                    }
                }
                chain
            })
            .collect();
        let mut corridors = Vec::with_capacity(lanelets.len());
        for a in 0..lanelets.len() {
            let mut order = vec![a];
            let mut x = a;
            while let Some(&p) = lanelets[x].predecessors.first() {
                if order.contains(&p) {
                    break;
                }
                order.insert(0, p);
                x = p;
            }
            x = a;
            while let Some(&s) = lanelets[x].successors.first() {
                if order.contains(&s) {
                    break;
                }
                order.push(s);
                x = s;
            }
            let points = order
                .iter()
                .flat_map(|&i| lanelets[i].centre.points().iter().copied());
            let line = Polyline::new(points)
                .ok_or_else(|| invalid(lanelets[a].id, "the corridor has zero length"))?;
            corridors.push(line);
        }
        Ok(Self {
            lanelets,
            chains,
            corridors,
        })
    }

    /// The lanelet containing `p`; where lanelets overlap, the one whose centre is nearest.
    pub fn locate(&self, p: Point) -> Option<usize> {
        let mut best: Option<(f64, usize)> = None;
        for (i, l) in self.lanelets.iter().enumerate() {
            let [x0, y0, x1, y1] = l.bbox;
            if p[0] < x0 || p[0] > x1 || p[1] < y0 || p[1] > y1 || !contains(&l.ring, p) {
                continue;
            }
            let d = l.centre.project(p).d.abs();
            if best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, i));
            }
        }
        best.map(|(_, i)| i)
    }

    /// Whether `b` follows `a` along successors or precedes it along predecessors.
    pub fn longitudinal(&self, a: usize, b: usize) -> bool {
        self.chains[a].contains(&b)
    }

    /// The side on which `b` lies next to `a`: some lanelet of `a`'s chain is adjacent (same
    /// driving direction) to some lanelet of `b`'s chain.
    pub fn lateral(&self, a: usize, b: usize) -> Option<Direction> {
        for &x in &self.chains[a] {
            let l = &self.lanelets[x];
            for (adjacent, direction) in [
                (l.adjacent_left, Direction::Left),
                (l.adjacent_right, Direction::Right),
            ] {
                if adjacent.is_some_and(|y| self.chains[b].contains(&y)) {
                    return Some(direction);
                }
            }
        }
        None
    }

    /// The corridor of lanelet `a`.
    pub fn corridor(&self, a: usize) -> &Polyline {
        &self.corridors[a]
    }

    /// The last point of `a`'s corridor (where its lane leaves the map or ends).
    pub fn corridor_end(&self, a: usize) -> Point {
        let points = self.corridors[a].points();
        points[points.len() - 1]
    }
}
