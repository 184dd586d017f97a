//! What the Review view plots of a replay, in memory that does not grow with the
//! trace: the monitor's time in at most [`MAX_BINS`] equal bins (their width doubled,
//! neighbours merged, as the trace grows), each with every curve's lowest and highest
//! value and the most severe state in it. The page draws any zoom from them, the
//! lowest and highest per pixel column, so that a one-sample spike stays visible.
//! As the monitor example's figure, only a new reading adds to the curves: a stop or
//! a fault shows as a gap, not the last value held.

use misalign::monitor::{Reading, RiskState};

/// At most this many bins (a 1 000 000-sample trace at 1 s keeps 8 s bins: 5 MB).
pub const MAX_BINS: usize = 1 << 17;

/// The curves, in the page's order (its legend gives the units).
pub const CURVES: [&str; 5] = ["d/b", "margin (mrad)", "F (N)", "P (kN)", "phi (mrad)"];

/// No state in a bin.
pub const NO_STATE: u8 = u8::MAX;

/// The timeline of a replay, binned.
#[derive(Debug, Clone)]
pub struct Bins {
    bin_ms: u64,
    low: Vec<[f32; 5]>,
    high: Vec<[f32; 5]>,
    state: Vec<u8>,
    last_reading: Option<Reading>,
}

impl Default for Bins {
    fn default() -> Self {
        Bins::new()
    }
}

impl Bins {
    /// Empty, bins of 1 ms until wider ones are needed.
    pub const fn new() -> Self {
        Bins {
            bin_ms: 1,
            low: Vec::new(),
            high: Vec::new(),
            state: Vec::new(),
            last_reading: None,
        }
    }

    /// The bin of `elapsed_ms`, neighbours merged pairwise until it fits.
    fn bin(&mut self, elapsed_ms: u64) -> usize {
        while elapsed_ms / self.bin_ms >= MAX_BINS as u64 {
            let pairs = self.state.len().div_ceil(2);
            for i in 0..pairs {
                let (a, b) = (2 * i, (2 * i + 1).min(self.state.len() - 1));
                for k in 0..CURVES.len() {
                    // f32::min and max take the number over NaN (an empty bin).
                    self.low[i][k] = self.low[a][k].min(self.low[b][k]);
                    self.high[i][k] = self.high[a][k].max(self.high[b][k]);
                }
                self.state[i] = worse(self.state[a], self.state[b]);
            }
            self.low.truncate(pairs);
            self.high.truncate(pairs);
            self.state.truncate(pairs);
            self.bin_ms *= 2;
        }
        let i = (elapsed_ms / self.bin_ms) as usize;
        if self.state.len() <= i {
            self.low.resize(i + 1, [f32::NAN; 5]);
            self.high.resize(i + 1, [f32::NAN; 5]);
            self.state.resize(i + 1, NO_STATE);
        }
        i
    }

    /// A sample's outcome: the monitor's time (ms since the first sample), its state
    /// and its reading after it.
    pub fn add(&mut self, elapsed_ms: u64, state: RiskState, reading: Option<Reading>) {
        let fresh = reading.is_some() && reading != self.last_reading;
        self.last_reading = reading;
        let i = self.bin(elapsed_ms);
        self.state[i] = worse(self.state[i], state.index() as u8);
        if let (true, Some(r)) = (fresh, reading) {
            let values = [
                r.slip_ratio,
                r.margin.map_or(f32::NAN, |m| m * 1e3),
                r.axial_force,
                r.load * 1e-3,
                r.phi * 1e3,
            ];
            let (low, high) = (&mut self.low[i], &mut self.high[i]);
            for (k, v) in values.into_iter().enumerate() {
                // Comparisons, not f32::min (a libm call in WebAssembly); an empty
                // bin's NaN is replaced by the first value.
                if v.is_finite() {
                    if low[k].is_nan() || v < low[k] {
                        low[k] = v;
                    }
                    if high[k].is_nan() || v > high[k] {
                        high[k] = v;
                    }
                }
            }
        }
    }

    /// A bin's width (s).
    pub fn bin_s(&self) -> f64 {
        self.bin_ms as f64 / 1e3
    }

    /// How many bins.
    pub fn len(&self) -> usize {
        self.state.len()
    }

    /// Whether no sample was added.
    pub fn is_empty(&self) -> bool {
        self.state.is_empty()
    }

    /// Curve `k`'s lowest value in each bin (NaN where none).
    pub fn low(&self, k: usize) -> Vec<f32> {
        self.low
            .iter()
            .map(|b| b.get(k).copied().unwrap_or(f32::NAN))
            .collect()
    }

    /// Curve `k`'s highest value in each bin.
    pub fn high(&self, k: usize) -> Vec<f32> {
        self.high
            .iter()
            .map(|b| b.get(k).copied().unwrap_or(f32::NAN))
            .collect()
    }

    /// Each bin's most severe state ([`RiskState::index`], [`NO_STATE`] none).
    pub fn states(&self) -> Vec<u8> {
        self.state.clone()
    }
}

/// The more severe of two states (by `RiskState::index`: stopped, normal, microslip,
/// gross slip, sensor fault), `NO_STATE` the least.
fn worse(a: u8, b: u8) -> u8 {
    match (a, b) {
        (NO_STATE, x) | (x, NO_STATE) => x,
        (a, b) => a.max(b),
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

    /// What is kept does not grow with the trace, and a one-sample spike is still in
    /// its bin, as are the state it raised and a gap while stopped.
    #[test]
    fn bounded_with_spikes_states_and_gaps() {
        let mut b = Bins::new();
        let n = 1_000_000u64;
        let spike = n / 3 + 17;
        for i in 0..n {
            let (state, r) = match i {
                _ if i == spike => (RiskState::GrossSlip, reading(7.5)),
                _ if (500_000..500_300).contains(&i) => (RiskState::Stopped, None),
                _ => (RiskState::Normal, reading(0.5 + 1e-3 * (i % 100) as f32)),
            };
            b.add(i * 1000, state, r);
        }
        assert!(b.len() <= MAX_BINS && b.len() > MAX_BINS / 2, "{}", b.len());
        assert_eq!(b.bin_s(), 8.192);
        let at = (spike as f64 / b.bin_s()) as usize;
        assert_eq!(b.high(0)[at], 7.5);
        assert_eq!(b.states()[at], RiskState::GrossSlip.index() as u8);
        let stopped = (500_100.0 / b.bin_s()) as usize;
        assert!(b.high(0)[stopped].is_nan());
        assert_eq!(b.states()[stopped], RiskState::Stopped.index() as u8);
        assert!(b.low(0).iter().filter(|x| !x.is_nan()).all(|&x| x >= 0.5));
    }
}
