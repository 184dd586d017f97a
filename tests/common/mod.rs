//! Shared helpers for the integration tests: the independent reference data in
//! `tests/data/` (or `$MISALIGN_REFERENCE_DIR`) and error measures.
#![allow(dead_code)]

use std::collections::HashMap;
use std::path::PathBuf;

/// The folder of the independent 50-digit reference values.
pub fn reference_dir() -> PathBuf {
    match std::env::var_os("MISALIGN_REFERENCE_DIR") {
        Some(d) => PathBuf::from(d),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data"),
    }
}

/// One CSV row as column name -> text.
pub type Row = HashMap<String, String>;

/// All rows of a reference file; panics with the path if it cannot be read.
pub fn read_rows(name: &str) -> Vec<Row> {
    let path = reference_dir().join(name);
    let mut reader = csv::Reader::from_path(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let headers = reader.headers().unwrap().clone();
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            headers
                .iter()
                .zip(r.iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

/// A column of a row as f64 (`inf` allowed).
pub fn num(row: &Row, key: &str) -> f64 {
    row[key]
        .parse()
        .unwrap_or_else(|_| panic!("column {key}: {:?}", row[key]))
}

/// The data's phi0 (rad), NaN where it passes pi/2: eq (4) with unequal radii gives
/// phi0 = theta0 / c beyond a right angle while theta0 is below it, where every model
/// answers no critical angle (NaN in the CSV tools' and the batch's numbers).
pub fn phi0(row: &Row) -> f64 {
    let p = num(row, "phi0");
    if p > core::f64::consts::FRAC_PI_2 {
        f64::NAN
    } else {
        p
    }
}

/// The data's theta0, NaN where its phi0 passes pi/2 (no critical angle: [`phi0`]).
pub fn theta0(row: &Row) -> f64 {
    if phi0(row).is_nan() {
        f64::NAN
    } else {
        num(row, "theta0")
    }
}

/// A number of the CSV tools' output: an empty field (no value) is NaN.
pub fn num_or_nan(row: &Row, key: &str) -> f64 {
    if row[key].is_empty() {
        f64::NAN
    } else {
        num(row, key)
    }
}

/// Relative error of `got` against `want`; exact zeros, equal infinities and two NaN
/// (both "none", see [`phi0`]) give 0.
pub fn rel_err(got: f64, want: f64) -> f64 {
    if got == want || (got.is_nan() && want.is_nan()) {
        0.0
    } else {
        ((got - want) / want).abs()
    }
}

/// Tracks the worst relative error per quantity, with the row where it occurred.
#[derive(Default)]
pub struct Worst {
    entries: Vec<(String, f64, usize)>,
}

impl Worst {
    /// Records the error of `got` against `want` for quantity `what` on row `row`.
    pub fn add(&mut self, what: &str, row: usize, got: f64, want: f64) {
        let e = rel_err(got, want);
        let e = if e.is_nan() { f64::INFINITY } else { e };
        match self.entries.iter_mut().find(|(w, _, _)| w == what) {
            Some(entry) => {
                if e > entry.1 {
                    *entry = (what.to_string(), e, row);
                }
            }
            None => self.entries.push((what.to_string(), e, row)),
        }
    }

    /// Panics, listing every quantity, if any worst error exceeds `bound`.
    pub fn assert_below(&self, bound: f64) {
        let report: Vec<String> = self
            .entries
            .iter()
            .map(|(w, e, r)| format!("{w}: {e:.3e} (row {r})"))
            .collect();
        println!("worst relative errors: {}", report.join(", "));
        assert!(!self.entries.is_empty(), "nothing was compared");
        for (w, e, r) in &self.entries {
            assert!(
                *e <= bound,
                "{w}: relative error {e:.3e} at row {r} exceeds {bound:e}"
            );
        }
    }
}
