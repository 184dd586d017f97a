//! What the monitor's figures keep of a replay, in memory that does not grow with the
//! trace: the timeline in at most [`2 * COLUMNS`](COLUMNS) time bins, each holding
//! every curve's minimum and maximum (with their times, so that a one-sample spike is
//! drawn) and whether an event fell in it; the operating points (P, |phi|) evenly
//! decimated to at most [`MAX_SCATTER`].

use misalign::monitor::{EventKind, Reading, RiskState};

/// The timeline keeps between `COLUMNS` and `2 * COLUMNS` bins once it spans more
/// than `COLUMNS` ms (about one per pixel column of the 1000-pixel figure, or two).
pub const COLUMNS: usize = 1000;

/// At most this many operating points for the thresholds figure.
pub const MAX_SCATTER: usize = 4000;

/// The timeline's curves, in the figure's panel order.
pub const CURVES: [&str; 4] = ["d/b", "margin (mrad)", "F (N)", "state"];

/// The lowest and highest value of a curve in a bin, each with its time (s), and the
/// times of its first and last value there (where a gap before or after it starts).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extremes {
    /// (t, value) of the minimum.
    pub min: (f64, f32),
    /// (t, value) of the maximum.
    pub max: (f64, f32),
    /// The first value's time (s).
    pub first: f64,
    /// The last value's time (s).
    pub last: f64,
}

impl Extremes {
    fn add(slot: &mut Option<Extremes>, t: f64, v: f32) {
        match slot {
            None => {
                *slot = Some(Extremes {
                    min: (t, v),
                    max: (t, v),
                    first: t,
                    last: t,
                });
            }
            Some(e) => {
                if v < e.min.1 {
                    e.min = (t, v);
                }
                if v > e.max.1 {
                    e.max = (t, v);
                }
                e.first = e.first.min(t);
                e.last = e.last.max(t);
            }
        }
    }

    fn merge(slot: &mut Option<Extremes>, other: Option<Extremes>) {
        if let Some(o) = other {
            Extremes::add(slot, o.min.0, o.min.1);
            Extremes::add(slot, o.max.0, o.max.1);
            if let Some(e) = slot {
                e.first = e.first.min(o.first);
                e.last = e.last.max(o.last);
            }
        }
    }

    /// The extremes as points in time order (one when they coincide).
    pub fn points(self) -> impl Iterator<Item = (f64, f32)> {
        let (a, b) = if self.min.0 <= self.max.0 {
            (self.min, self.max)
        } else {
            (self.max, self.min)
        };
        std::iter::once(a).chain((a != b).then_some(b))
    }
}

/// One time bin.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Bin {
    /// Each curve's extremes ([`CURVES`]), `None` where it had no value.
    pub curves: [Option<Extremes>; 4],
    /// The first state change's time (s) in the bin.
    pub state_change: Option<f64>,
    /// The first `approaching` or friction event's time (s) in the bin.
    pub alert: Option<f64>,
}

impl Bin {
    fn merge(&mut self, other: &Bin) {
        for (mine, theirs) in self.curves.iter_mut().zip(other.curves) {
            Extremes::merge(mine, theirs);
        }
        self.state_change = self.state_change.or(other.state_change);
        self.alert = self.alert.or(other.alert);
    }
}

/// The timeline of a replay, binned.
#[derive(Debug, Clone)]
pub struct Timeline {
    bin_ms: u64,
    bins: Vec<Bin>,
    end_ms: u64,
    last_reading: Option<Reading>,
}

impl Default for Timeline {
    fn default() -> Self {
        Timeline::new()
    }
}

impl Timeline {
    /// An empty timeline (bins of 1 ms until it needs wider ones).
    pub fn new() -> Self {
        Timeline {
            bin_ms: 1,
            bins: Vec::new(),
            end_ms: 0,
            last_reading: None,
        }
    }

    /// The bin of `elapsed_ms`, the bins merged pairwise until it fits.
    fn bin(&mut self, elapsed_ms: u64) -> &mut Bin {
        self.end_ms = self.end_ms.max(elapsed_ms);
        while elapsed_ms / self.bin_ms >= 2 * COLUMNS as u64 {
            let merged: Vec<Bin> = self
                .bins
                .chunks(2)
                .map(|pair| {
                    let mut b = pair[0];
                    if let Some(second) = pair.get(1) {
                        b.merge(second);
                    }
                    b
                })
                .collect();
            self.bins = merged;
            self.bin_ms *= 2;
        }
        let i = (elapsed_ms / self.bin_ms) as usize;
        if self.bins.len() <= i {
            self.bins.resize(i + 1, Bin::default());
        }
        &mut self.bins[i]
    }

    /// A sample's outcome: the monitor's time, state and reading after it. Only a new
    /// reading (not while stopped or faulted) adds to d/b, the margin and F, so that
    /// the figure shows gaps there, not the last value held; the state always.
    /// Returns whether the reading was new.
    pub fn add(&mut self, elapsed_ms: u64, state: RiskState, reading: Option<Reading>) -> bool {
        let fresh = reading.is_some() && reading != self.last_reading;
        self.last_reading = reading;
        let t = elapsed_ms as f64 / 1e3;
        let bin = self.bin(elapsed_ms);
        if let (true, Some(r)) = (fresh, reading) {
            let values = [
                Some(r.slip_ratio),
                r.margin.map(|m| m * 1e3),
                Some(r.axial_force),
            ];
            for (slot, v) in bin.curves.iter_mut().zip(values) {
                if let Some(v) = v.filter(|v| v.is_finite()) {
                    Extremes::add(slot, t, v);
                }
            }
        }
        Extremes::add(&mut bin.curves[3], t, state.index() as f32);
        fresh
    }

    /// An event at `elapsed_ms`.
    pub fn event(&mut self, elapsed_ms: u64, kind: &EventKind) {
        let t = elapsed_ms as f64 / 1e3;
        let bin = self.bin(elapsed_ms);
        let slot = match kind {
            EventKind::StateChange { .. } => &mut bin.state_change,
            EventKind::Approaching { .. } | EventKind::Friction { .. } | EventKind::Fieldbus(_) => {
                &mut bin.alert
            }
        };
        slot.get_or_insert(t);
    }

    /// The bins, in time order.
    pub fn bins(&self) -> &[Bin] {
        &self.bins
    }

    /// The last time added (s).
    pub fn end_s(&self) -> f64 {
        self.end_ms as f64 / 1e3
    }

    /// Curve `k` ([`CURVES`]) as points (t in s) in time order: each bin's minimum and
    /// maximum.
    pub fn curve(&self, k: usize) -> impl Iterator<Item = (f64, f32)> + '_ {
        self.extremes(k).flat_map(Extremes::points)
    }

    fn extremes(&self, k: usize) -> impl Iterator<Item = Extremes> + '_ {
        self.bins
            .iter()
            .filter_map(move |b| b.curves.get(k).copied().flatten())
    }

    /// Curve `k` as runs of points, a new run where no value came for more than
    /// `gap_s` (s): a stop, a fault or a dropout; a gap within one bin is too short to
    /// see.
    pub fn runs(&self, k: usize, gap_s: f64) -> Vec<Vec<(f64, f32)>> {
        let mut runs: Vec<Vec<(f64, f32)>> = Vec::new();
        let mut last = f64::NEG_INFINITY;
        for e in self.extremes(k) {
            if runs.is_empty() || e.first - last > gap_s {
                runs.push(Vec::new());
            }
            if let Some(run) = runs.last_mut() {
                run.extend(e.points());
            }
            last = e.last;
        }
        runs
    }
}

/// Points kept evenly: every `step`-th offered, `step` doubling whenever more than
/// [`MAX_SCATTER`] are kept.
#[derive(Debug, Clone)]
pub struct Decimated<T> {
    step: u64,
    offered: u64,
    points: Vec<T>,
}

impl<T> Default for Decimated<T> {
    fn default() -> Self {
        Decimated {
            step: 1,
            offered: 0,
            points: Vec::new(),
        }
    }
}

impl<T> Decimated<T> {
    /// Offers a point.
    pub fn add(&mut self, point: T) {
        if self.offered.is_multiple_of(self.step) {
            self.points.push(point);
            if self.points.len() > MAX_SCATTER {
                let mut i = 0;
                self.points.retain(|_| {
                    i += 1;
                    i % 2 == 1
                });
                self.step *= 2;
            }
        }
        self.offered += 1;
    }

    /// The points kept, in the order offered.
    pub fn points(&self) -> &[T] {
        &self.points
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reading(s: f32) -> Option<Reading> {
        Some(Reading {
            load: 2000.0,
            phi: 1e-4,
            slip_ratio: s,
            axial_force: 10.0 * s,
            critical_angle: Some(1e-3),
            margin: Some(1e-3 * (1.0 - s)),
        })
    }

    /// A replay of `n` samples at 1 s, d/b a slow ramp with one spike at `spike`.
    fn timeline(n: u64, spike: u64) -> Timeline {
        let mut t = Timeline::new();
        for i in 0..n {
            let s = if i == spike {
                7.5
            } else {
                0.5 + 1e-3 * (i % 100) as f32
            };
            t.add(i * 1000, RiskState::Normal, reading(s));
        }
        t
    }

    /// What is kept does not grow with the trace: the same bound for 1e5 and 1e6
    /// samples, and a one-sample spike is still in the curve.
    #[test]
    fn the_timeline_is_bounded_and_keeps_spikes() {
        for n in [100_000, 1_000_000] {
            let spike = n / 3 + 17;
            let t = timeline(n, spike);
            assert!(
                (COLUMNS..2 * COLUMNS).contains(&t.bins().len()),
                "{n}: {}",
                t.bins().len()
            );
            assert!(t.curve(0).count() <= 4 * COLUMNS);
            let top = t
                .curve(0)
                .fold((0.0, 0.0f32), |a, p| if p.1 > a.1 { p } else { a });
            assert_eq!(top, (spike as f64, 7.5), "{n}");
            // F, a curve of its own, keeps it too.
            assert!(t.curve(2).any(|p| p == (spike as f64, 75.0)));
            assert_eq!(t.end_s(), (n - 1) as f64);
        }
    }

    /// Bins wider than the gap do not break a continuous curve; a dropout does.
    #[test]
    fn runs_break_at_dropouts_only() {
        let mut t = Timeline::new();
        for i in 0..200_000u64 {
            let dropout = (100_000..100_300).contains(&i);
            let r = if dropout {
                None
            } else {
                reading(0.5 + 1e-3 * (i % 10) as f32)
            };
            t.add(i * 1000, RiskState::Normal, r);
        }
        let runs = t.runs(0, 60.0);
        assert_eq!(runs.len(), 2);
        assert!(runs[0].last().unwrap().0 < 100_000.0 && runs[1][0].0 >= 100_300.0);
        assert_eq!(t.runs(3, 60.0).len(), 1);
    }

    #[test]
    fn a_short_replay_keeps_every_sample() {
        let t = timeline(500, 1000);
        assert_eq!(t.curve(3).count(), 500);
        // A repeated reading is not a new point.
        let mut r = Timeline::new();
        r.add(0, RiskState::Normal, reading(0.5));
        r.add(1, RiskState::Normal, reading(0.5));
        assert_eq!((r.curve(0).count(), r.curve(3).count()), (1, 2));
    }

    #[test]
    fn decimation_keeps_evenly_and_boundedly() {
        for n in [10_000u64, 1_000_000] {
            let mut d = Decimated::default();
            (0..n).for_each(|i| d.add(i));
            let p = d.points();
            assert!(p.len() <= MAX_SCATTER && p.len() > MAX_SCATTER / 2, "{n}");
            let step = p[1] - p[0];
            assert!(p.windows(2).all(|w| w[1] - w[0] == step));
        }
    }
}
