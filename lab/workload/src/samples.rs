//! The benchmark's samples on the demo scene (`misalign::Scene::DEMO`), shared by the
//! host benchmark and the benchmark image: a few hundred (P, phi) over the practical
//! domain (theta ~ 1e-5 to 1e-2, loads from 50 N to 5 kN on printing-press rollers),
//! the same on every run.

/// Largest load in the samples (N).
pub const LOAD_MAX: f64 = 5000.0;

/// `n` samples, log-spaced in phi (1e-5 to 1e-2 rad) and in P (50 N to 5 kN), with
/// alternating sign of phi; a fixed low-discrepancy walk, no random generator.
pub fn practical(n: usize) -> impl Iterator<Item = (f64, f64)> {
    (0..n).map(move |i| {
        let u = (i as f64 + 0.5) / n as f64;
        let w = (i as f64) * 0.618_033_988_749_894_9;
        let v = w - libm::floor(w);
        let phi = 1e-5 * libm::pow(1e3, u);
        let load = 50.0 * libm::pow(100.0, v);
        (load, if i % 2 == 0 { phi } else { -phi })
    })
}
