//! What a period map's orbit keeps of itself (for basins of attraction):
//! its iterates after a transient, and, when asked, an early stop for an
//! orbit that has settled on a cycle (its record then completed by the
//! cycle repeated: what a longer run would record, to within the
//! settling tolerance) or that has reached an attractor already known
//! (its record then that attractor's). Orbits that stop early free their
//! lanes for the next orbit, so a map costs the periods its orbits need
//! to settle, not the whole transient.

use std::collections::HashMap;

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

/// Attractors found before, by the cells of the state space (side
/// `cell`, angles in [−π, π)) their records visit.
#[derive(Debug, Default)]
pub struct KnownAttractors {
    cell: f64,
    cells: HashMap<Vec<i64>, usize>,
    records: Vec<Vec<Vec<f64>>>,
}

impl KnownAttractors {
    /// No attractor yet; cells of side `cell`.
    pub fn new(cell: f64) -> KnownAttractors {
        KnownAttractors {
            cell,
            ..Default::default()
        }
    }
    /// Adds an attractor by the records of the orbits on it (angles
    /// wrapped; the first stands for it): its cells are those they visit
    /// (a cell already claimed stays with its first attractor).
    pub fn add(&mut self, records: &[&Vec<Vec<f64>>]) {
        let Some(&first) = records.first() else {
            return;
        };
        let index = self.records.len();
        let mut key = Vec::new();
        for y in records.iter().copied().flatten() {
            cell_of(y, self.cell, &mut key);
            self.cells.entry(key.clone()).or_insert(index);
        }
        self.records.push(first.clone());
    }
    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }
}

/// The cell of the state `y` (angles wrapped) into `key`.
pub fn cell_of(y: &[f64], cell: f64, key: &mut Vec<i64>) {
    key.clear();
    key.extend(y.iter().map(|x| (x / cell).floor() as i64));
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
    wrapped: Vec<f64>,
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
            wrapped: Vec::new(),
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
            self.wrapped.clear();
            self.wrapped
                .extend(y.iter().zip(self.wrap).map(|(&x, &angle)| {
                    if angle {
                        crate::analysis::period_map::wrap_angle(x)
                    } else {
                        x
                    }
                }));
            cell_of(&self.wrapped, known.cell, &mut self.key);
            self.streak = match known.cells.get(&self.key) {
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
        a.iter().zip(b).zip(self.wrap).all(|((x, y), &angle)| {
            let d = x - y;
            let d = if angle {
                crate::analysis::period_map::wrap_angle(d)
            } else {
                d
            };
            d.abs() <= tolerance
        })
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
