//! What a period map's orbit keeps of itself (for basins of attraction):
//! its iterates after a transient, and, when asked, an early stop for an
//! orbit that has settled on a cycle (its record then completed by the
//! cycle repeated: what a longer run would record, to within the
//! settling tolerance) or that has reached an attractor already known
//! (its record then that attractor's). Orbits that stop early free their
//! lanes for the next orbit, so a map costs the periods its orbits need
//! to settle, not the whole transient.

use std::collections::HashMap;
use std::f64::consts::{PI, TAU};

/// How each orbit is recorded.
pub struct Recording<'a> {
    /// Periods run before the record, then the iterates recorded.
    pub transient: usize,
    pub record: usize,
    /// With Some(tolerance): an orbit whose iterate is within `tolerance`
    /// of the one k periods before (every component; angles modulo 2π),
    /// for the least such k ≤ record/2, stops there.
    pub settle: Option<f64>,
    /// Attractors found before: an orbit whose `record` consecutive
    /// iterates lie in cells of one of them stops there, its record that
    /// attractor's (the evidence a record gives of its attractor).
    pub known: Option<&'a KnownAttractors>,
    /// Called with the number of orbits done, as blocks of them end
    /// (progress).
    pub done: &'a (dyn Fn(usize) + Sync),
}

/// The cells of the state space that identify attractors: cubes of side
/// `side`; along an angle, the circle is cut into whole cells (the last a
/// little wider), so that cells across ±π are neighbours.
#[derive(Clone, Debug, Default)]
pub struct Cells {
    side: f64,
    /// Per component: how many cells go around it, for an angle.
    around: Vec<Option<i64>>,
}

impl Cells {
    /// Cells of side `side` for a state whose components `wrap` are angles.
    pub fn new(side: f64, wrap: &[bool]) -> Cells {
        let around = wrap
            .iter()
            .map(|&angle| angle.then(|| ((TAU / side).floor() as i64).max(1)))
            .collect();
        Cells { side, around }
    }

    /// The cell of the state `y` into `key`.
    pub fn of(&self, y: &[f64], key: &mut Vec<i64>) {
        key.clear();
        key.extend(y.iter().zip(&self.around).map(|(&x, around)| match around {
            Some(n) => {
                let from_minus_pi = crate::ode::wrap_angle(x) + PI;
                ((from_minus_pi / self.side).floor() as i64).clamp(0, n - 1)
            }
            None => (x / self.side).floor() as i64,
        }));
    }

    /// Calls `visit` with each cell that touches `cell` (a face or a
    /// corner, around the circle for an angle), `cell` itself included.
    pub fn touching(&self, cell: &[i64], mut visit: impl FnMut(&[i64])) {
        let mut neighbour = Vec::with_capacity(cell.len());
        for offset in 0..3usize.pow(cell.len() as u32) {
            neighbour.clear();
            neighbour.extend(
                cell.iter()
                    .zip(&self.around)
                    .enumerate()
                    .map(|(i, (c, around))| {
                        let moved = c + (offset / 3usize.pow(i as u32) % 3) as i64 - 1;
                        around.map_or(moved, |n| moved.rem_euclid(n))
                    }),
            );
            visit(&neighbour);
        }
    }
}

/// Attractors found before, by the cells their records visit.
#[derive(Debug, Default)]
pub struct KnownAttractors {
    cells: Cells,
    owner: HashMap<Vec<i64>, usize>,
    records: Vec<Vec<Vec<f64>>>,
}

impl KnownAttractors {
    /// No attractor yet.
    pub fn new(cells: Cells) -> KnownAttractors {
        KnownAttractors {
            cells,
            ..Default::default()
        }
    }
    /// Adds an attractor by the records of the orbits on it (the first
    /// stands for it): its cells are those they visit (a cell already
    /// claimed stays with its first attractor).
    pub fn add(&mut self, records: &[&Vec<Vec<f64>>]) {
        let Some(&first) = records.first() else {
            return;
        };
        let index = self.records.len();
        let mut key = Vec::new();
        for y in records.iter().copied().flatten() {
            self.cells.of(y, &mut key);
            self.owner.entry(key.clone()).or_insert(index);
        }
        self.records.push(first.clone());
    }
    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }
}

/// The largest difference of the states' components (the angles `wrap`
/// modulo 2π).
pub fn distance(a: &[f64], b: &[f64], wrap: &[bool]) -> f64 {
    a.iter()
        .zip(b)
        .zip(wrap)
        .map(|((x, y), &angle)| match angle {
            true => crate::ode::wrap_angle(x - y).abs(),
            false => (x - y).abs(),
        })
        .fold(0.0, f64::max)
}

/// Whether the states `a` and `b` differ by at most `tolerance` in every
/// component (the angles `wrap` modulo 2π).
pub fn within(a: &[f64], b: &[f64], wrap: &[bool], tolerance: f64) -> bool {
    distance(a, b, wrap) <= tolerance
}

/// One orbit's record as it runs.
pub(crate) struct Recorder<'a> {
    plan: &'a Recording<'a>,
    /// Which components are angles.
    wrap: &'a [bool],
    seen: usize,
    /// The last record/2 + 1 iterates (for the settling test), a ring:
    /// `stored` of them, the next written at slot `next`.
    recent: Vec<f64>,
    stored: usize,
    next: usize,
    kept: Vec<Vec<f64>>,
    /// The period of the cycle it settled on.
    settled: Option<usize>,
    /// The known attractor its last iterates' cells belong to, how many
    /// consecutive iterates, and the cell of the last (a buffer).
    streak: (usize, usize),
    key: Vec<i64>,
    /// The known attractor it reached.
    recognised: Option<usize>,
}

impl<'a> Recorder<'a> {
    pub(crate) fn new(plan: &'a Recording<'a>, wrap: &'a [bool]) -> Recorder<'a> {
        Recorder {
            plan,
            wrap,
            seen: 0,
            recent: Vec::new(),
            stored: 0,
            next: 0,
            kept: Vec::with_capacity(plan.record),
            settled: None,
            streak: (usize::MAX, 0),
            key: Vec::new(),
            recognised: None,
        }
    }

    /// Takes the next iterate; whether the orbit goes on.
    pub(crate) fn push(&mut self, y: &[f64]) -> bool {
        self.seen += 1;
        if self.seen > self.plan.transient {
            self.kept.push(y.to_vec());
        }
        if self.seen >= self.plan.transient + self.plan.record {
            return false;
        }
        if let Some(known) = self.plan.known {
            known.cells.of(y, &mut self.key);
            self.streak = match known.owner.get(&self.key) {
                Some(&a) if a == self.streak.0 => (a, self.streak.1 + 1),
                Some(&a) => (a, 1),
                None => (usize::MAX, 0),
            };
            if self.streak.1 >= self.plan.record {
                self.recognised = Some(self.streak.0);
                return false;
            }
        }
        let Some(tolerance) = self.plan.settle else {
            return true;
        };
        let slots = self.plan.record / 2 + 1;
        let n = y.len();
        self.recent.resize(slots * n, 0.0);
        self.recent[self.next * n..(self.next + 1) * n].copy_from_slice(y);
        self.next = (self.next + 1) % slots;
        self.stored = (self.stored + 1).min(slots);
        self.settled =
            (1..self.stored).find(|&k| self.close(self.back(0), self.back(k), tolerance));
        self.settled.is_none()
    }

    /// The iterate `k` periods before the last one (k < stored).
    fn back(&self, k: usize) -> &[f64] {
        let slots = self.plan.record / 2 + 1;
        let n = self.recent.len() / slots;
        let slot = (self.next + 2 * slots - 1 - k) % slots;
        &self.recent[slot * n..(slot + 1) * n]
    }

    fn close(&self, a: &[f64], b: &[f64], tolerance: f64) -> bool {
        within(a, b, self.wrap, tolerance)
    }

    /// The record, if the orbit ran to its end (`ran`: it stopped without
    /// an error) or settled: the settled cycle's last k iterates repeated
    /// after the last one seen.
    pub(crate) fn finish(mut self, ran: bool) -> Option<Vec<Vec<f64>>> {
        if !ran {
            return None;
        }
        if let (Some(a), Some(known)) = (self.recognised, self.plan.known) {
            return Some(known.records[a].clone());
        }
        if let Some(k) = self.settled {
            // y_m = y_{m−k} on the cycle, for every m after the last seen.
            for m in self.seen + 1..=self.plan.transient + self.plan.record {
                if m > self.plan.transient {
                    let j = (m - self.seen - 1) % k;
                    self.kept.push(self.back(k - 1 - j).to_vec());
                }
            }
        }
        (self.kept.len() == self.plan.record).then_some(self.kept)
    }
}
