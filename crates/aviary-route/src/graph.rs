//! The visibility graph of one band of heights, and the A* search through it.

use aviary_api::geometry::dist;
use pathfinding::prelude::astar;

use crate::shape::Outline;
use crate::Airspace;

/// The corners a route may bend at, and which of them see each other. The corners of the
/// grown zones that hold in the band and lie outside every other one and inside the fence,
/// and the fence's own corners outside every grown zone (a route bends at an inward corner
/// of the fence).
#[derive(Debug)]
pub(crate) struct Graph {
    nodes: Vec<[f64; 2]>,
    /// For each node, the nodes it sees and the cost of going there.
    sees: Vec<Vec<(usize, Cost)>>,
}

/// Micrometres: A* wants a total order, which `f64` has not.
type Cost = u64;

fn cost(a: [f64; 2], b: [f64; 2]) -> Cost {
    (dist(a, b) * 1e6).round() as Cost
}

/// What a query's start and goal see, beside the graph: the lines from them are tested
/// against the grown zones, except that a line from an end that lies in a zone's margin
/// is tested against that zone itself (a drone at a place near a zone may leave it and
/// come back to it, keeping out of the zone).
pub(crate) struct Ends<'a> {
    space: &'a Airspace,
    held: &'a [usize],
    from: [f64; 2],
    to: [f64; 2],
    /// The zones (of `held`) in whose margin `from`, and `to`, lie.
    from_margin: Vec<usize>,
    to_margin: Vec<usize>,
    /// Whether routes keep to the fence (the start is inside it).
    fenced: bool,
}

impl<'a> Ends<'a> {
    pub fn new(
        space: &'a Airspace,
        held: &'a [usize],
        from: [f64; 2],
        to: [f64; 2],
        fenced: bool,
    ) -> Ends<'a> {
        let margin_of = |p: [f64; 2]| -> Vec<usize> {
            held.iter().copied().filter(|&i| space.zones[i].grown.holds(p)).collect()
        };
        Ends {
            space,
            held,
            from,
            to,
            from_margin: margin_of(from),
            to_margin: margin_of(to),
            fenced,
        }
    }

    /// Whether the straight line `a`-`b`, one of whose ends is the start or the goal, is
    /// clear.
    pub fn clear(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        let at_end = |i: usize| {
            let touches = |p: [f64; 2]| p == self.from || p == self.to;
            let margin = |p: [f64; 2]| {
                (p == self.from && self.from_margin.contains(&i))
                    || (p == self.to && self.to_margin.contains(&i))
            };
            (touches(a) && margin(a)) || (touches(b) && margin(b))
        };
        let zones_clear = self.held.iter().all(|&i| {
            let zone = &self.space.zones[i];
            let shape = if at_end(i) { &zone.outline } else { &zone.grown };
            !shape.crossed_by(a, b)
        });
        zones_clear && !(self.fenced && self.space.fence.as_ref().is_some_and(|f| f.left_by(a, b)))
    }
}

impl Graph {
    pub fn new(space: &Airspace, held: &[usize]) -> Graph {
        let grown: Vec<&Outline> = held.iter().map(|&i| &space.zones[i].grown).collect();
        let fence = space.fence.as_ref();
        let free = |p: [f64; 2]| {
            !grown.iter().any(|g| g.holds(p))
                && fence.is_none_or(|f| aviary_api::geometry::contains(&f.corners, p))
        };
        let corners = grown.iter().flat_map(|g| g.corners.iter().copied());
        let fence_corners = fence.into_iter().flat_map(|f| f.corners.iter().copied());
        let nodes: Vec<[f64; 2]> = corners.chain(fence_corners).filter(|&p| free(p)).collect();
        let mut sees: Vec<Vec<(usize, Cost)>> = vec![Vec::new(); nodes.len()];
        for i in 0..nodes.len() {
            for j in i + 1..nodes.len() {
                let (a, b) = (nodes[i], nodes[j]);
                let clear = !grown.iter().any(|g| g.crossed_by(a, b))
                    && !fence.is_some_and(|f| f.left_by(a, b));
                if clear {
                    sees[i].push((j, cost(a, b)));
                    sees[j].push((i, cost(a, b)));
                }
            }
        }
        Graph { nodes, sees }
    }

    /// The shortest way from the start to the goal through the graph (the start and the
    /// goal do not see each other): the points after the start, the goal last.
    pub fn search(&self, ends: &Ends) -> Option<Vec<[f64; 2]>> {
        // Node ids: 0 the start, 1 the goal, 2 + k the graph's node k.
        let from_sees: Vec<usize> =
            (0..self.nodes.len()).filter(|&k| ends.clear(ends.from, self.nodes[k])).collect();
        if from_sees.is_empty() {
            return None;
        }
        let to_seen: Vec<bool> = self.nodes.iter().map(|&p| ends.clear(p, ends.to)).collect();
        if !to_seen.contains(&true) {
            return None;
        }
        let at = |n: usize| match n {
            0 => ends.from,
            1 => ends.to,
            k => self.nodes[k - 2],
        };
        let successors = |&n: &usize| -> Vec<(usize, Cost)> {
            match n {
                0 => from_sees.iter().map(|&k| (k + 2, cost(ends.from, self.nodes[k]))).collect(),
                1 => Vec::new(),
                k => {
                    let k = k - 2;
                    let mut next: Vec<(usize, Cost)> =
                        self.sees[k].iter().map(|&(j, c)| (j + 2, c)).collect();
                    if to_seen[k] {
                        next.push((1, cost(self.nodes[k], ends.to)));
                    }
                    next
                }
            }
        };
        let heuristic = |&n: &usize| (dist(at(n), ends.to) * 1e6).floor() as Cost;
        let (path, _) = astar(&0usize, successors, heuristic, |&n| n == 1)?;
        Some(path.into_iter().skip(1).map(at).collect())
    }
}
