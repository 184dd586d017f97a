//! The exhaustive sweep's table (docs/sweep.csv).

use crate::records::SweepRow as Row;
use std::fmt::Write as _;

/// The table as Markdown (docs/measurements.md); `quick` says the f32 kernels were
/// strided.
pub fn markdown(rows: &[Row], quick: bool) -> String {
    let mut out = String::new();
    writeln!(
        out,
        "| kernel | domain | points | max error (ulps) | max relative error | worst at |"
    )
    .unwrap();
    writeln!(out, "|---|---|---|---|---|---|").unwrap();
    for r in rows {
        writeln!(
            out,
            "| `{}` | {} | {} | {:.2} | {:.2e} | {:.4e} |",
            r.kernel, r.domain, r.points, r.max_ulps, r.max_rel, r.at
        )
        .unwrap();
    }
    if quick {
        writeln!(out, "\n(quick pass: the f32 kernels strided)").unwrap();
    }
    out
}
