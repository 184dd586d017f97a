//! What one estimate of the reference costs, counted (test builds only): calls of
//! Carlson's R_D and evaluations of the function being solved, per estimate over the
//! host benchmark's samples (lab/workload/src/samples.rs: the demo scene, theta from
//! 1e-5 to 1e-2, loads from 50 N to 5 kN). `cargo test --lib cost -- --nocapture`.

use core::cell::Cell;

std::thread_local! {
    static RD_CALLS: Cell<u64> = const { Cell::new(0) };
    static RD_PAIRS: Cell<u64> = const { Cell::new(0) };
    static EVALUATIONS: Cell<u64> = const { Cell::new(0) };
}

/// One call of R_D.
pub(crate) fn count_rd() {
    RD_CALLS.with(|c| c.set(c.get() + 1));
}

/// One pair of R_D's computed in one duplication loop.
pub(crate) fn count_rd_pair() {
    RD_PAIRS.with(|c| c.set(c.get() + 1));
}

/// One evaluation of a function being solved for its root.
pub(crate) fn count_evaluation() {
    EVALUATIONS.with(|c| c.set(c.get() + 1));
}

/// `[R_D calls, R_D pairs, evaluations]` that `run` spends, on this thread.
pub(crate) fn counted(run: impl FnOnce()) -> [u64; 3] {
    let read = || {
        [
            RD_CALLS.with(Cell::get),
            RD_PAIRS.with(Cell::get),
            EVALUATIONS.with(Cell::get),
        ]
    };
    let before = read();
    run();
    let after = read();
    [0, 1, 2].map(|i| after[i] - before[i])
}

mod tests {
    use super::counted;
    use crate::Scene;
    use crate::reference::{elliptic, normal};

    /// The host benchmark's samples (lab/workload/src/samples.rs, `practical`).
    fn practical(n: usize) -> impl Iterator<Item = (f64, f64)> {
        (0..n).map(move |i| {
            let u = (i as f64 + 0.5) / n as f64;
            let w = (i as f64) * 0.618_033_988_749_894_9;
            let v = w - libm::floor(w);
            let phi = 1e-5 * libm::pow(1e3, u);
            let load = 50.0 * libm::pow(100.0, v);
            (load, if i % 2 == 0 { phi } else { -phi })
        })
    }

    #[test]
    fn evaluations_over_the_whole_range() {
        // theta over 1e-99 .. pi/2, and g over the same range: one solve each.
        let n = 400;
        let thetas = (0..n).map(|i| libm::pow(10.0, -99.0 + 99.2 * i as f64 / (n - 1) as f64));
        let [_, pairs, ev] = counted(|| {
            for theta in thetas.clone() {
                normal::ellipse_shape(libm::fmin(theta, core::f64::consts::FRAC_PI_2)).unwrap();
            }
        })
        .map(|c| c as f64 / n as f64);
        std::println!("ellipse_shape: {pairs:.2} R_D pairs, {ev:.2} evaluations per call");
        let gs: std::vec::Vec<f64> = thetas
            .map(|t| normal::ellipse_shape(libm::fmin(t, 1.5)).unwrap().g())
            .collect();
        let [_, pairs, ev] = counted(|| {
            for &g in &gs {
                normal::theta_for_g(g).unwrap();
            }
        })
        .map(|c| c as f64 / n as f64);
        std::println!("theta_for_g: {pairs:.2} R_D pairs, {ev:.2} evaluations per call");
        assert!(ev < 4.0);
    }

    #[test]
    fn calls_per_estimate() {
        let scene = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap();
        let n = 256;
        let [rd, pairs, ev] = counted(|| {
            for (load, phi) in practical(n) {
                elliptic(&scene, load, phi).unwrap();
            }
        })
        .map(|c| c as f64 / n as f64);
        std::println!(
            "per estimate: {rd:.1} R_D calls, {pairs:.1} R_D pairs (one duplication loop \
             each), {ev:.1} solver evaluations"
        );
    }
}
