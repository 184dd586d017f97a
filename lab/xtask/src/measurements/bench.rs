//! The speed-against-error tables (docs/bench.csv): the estimates with their targets,
//! every kernel's cost, the monitor's stages.

use crate::records::BenchRow;
use misalign_workload::{Model, Operation};
use std::fmt::Write as _;

/// The row of `(cpu, model, operation)`.
pub fn find<'a>(
    rows: &'a [BenchRow],
    cpu: &str,
    model: Model,
    op: Operation,
) -> Option<&'a BenchRow> {
    rows.iter()
        .find(|r| r.cpu == cpu && r.model == model.name() && r.operation == op.name())
}

/// `mean / max` of a row.
fn counts(r: &BenchRow) -> String {
    format!("{} / {}", r.mean, r.max)
}

/// An error as the tables print it (two digits), `-` where none was measured.
fn error(r: &BenchRow) -> String {
    r.error.map_or("-".to_string(), |e| format!("{e:.1e}"))
}

/// The estimates table: per CPU the full estimate of every model, with ratios to the
/// reference and to Hamrock & Brewe.
pub fn estimates(rows: &[BenchRow]) -> String {
    let mut s = String::new();
    writeln!(s, "| cpu | model | operation | instructions mean / max | max relative error | fewer instructions than the reference | more accurate than Hamrock & Brewe |").unwrap();
    writeln!(s, "|---|---|---|--:|--:|--:|--:|").unwrap();
    let estimate =
        |r: &&BenchRow| Operation::from_name(&r.operation).is_some_and(|o| o.is_estimate());
    for r in rows.iter().filter(estimate) {
        writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} |",
            r.cpu,
            r.model,
            r.operation,
            counts(r),
            error(r),
            fewer_instructions(rows, r),
            more_accurate(rows, r)
        )
        .unwrap();
    }
    s
}

/// A target of the elliptic estimate on one core: its mean instructions per call in
/// QEMU, its worst relative error and the bytes of table data it reads, at most these.
pub struct Target {
    pub cpu: &'static str,
    /// The core's name in prose.
    pub cpu_name: &'static str,
    pub model: Model,
    /// The model's name in prose.
    pub model_name: &'static str,
    pub instructions: u64,
    pub error: f64,
    pub table_bytes: Option<usize>,
}

/// The elliptic estimate's targets (the per-sample path at its limit): a full `cargo
/// xtask bench` fails over one, and a test holds the committed docs/bench.csv to them.
pub const TARGETS: [Target; 2] = [
    Target {
        cpu: "cortex-m4f",
        cpu_name: "Cortex-M4F",
        model: Model::F32,
        model_name: "f32",
        instructions: 100,
        error: 5e-7,
        table_bytes: Some(4096),
    },
    Target {
        cpu: "cortex-m0",
        cpu_name: "Cortex-M0",
        model: Model::Fixed,
        model_name: "fixed point",
        instructions: 350,
        error: 1e-5,
        table_bytes: None,
    },
];

/// The targets `rows` miss, one sentence each (a target without its row is missed).
pub fn missed_targets(rows: &[BenchRow]) -> Vec<String> {
    let mut missed = Vec::new();
    for t in &TARGETS {
        let what = format!("{} estimate on the {}", t.model_name, t.cpu_name);
        let Some(r) = find(rows, t.cpu, t.model, Operation::Estimate) else {
            missed.push(format!("{what}: not measured"));
            continue;
        };
        if r.mean > t.instructions {
            missed.push(format!(
                "{what}: {} instructions, target {}",
                r.mean, t.instructions
            ));
        }
        if !r.error.is_some_and(|e| e <= t.error) {
            missed.push(format!(
                "{what}: error {}, target {:.0e}",
                error(r),
                t.error
            ));
        }
        if let (Some(limit), Some(b)) = (t.table_bytes, table_bytes(t.model, Operation::Estimate))
            && b > limit
        {
            missed.push(format!("{what}: {b} bytes of tables, target {limit}"));
        }
    }
    missed
}

/// The targets and the figures `rows` give, as the measurements page states them below
/// the estimates' table.
pub fn targets_note(rows: &[BenchRow]) -> String {
    let parts: Vec<String> = TARGETS
        .iter()
        .map(|t| {
            let bytes = table_bytes(t.model, Operation::Estimate).unwrap_or(0);
            let (target_bytes, measured_bytes) = match t.table_bytes {
                Some(limit) => (
                    format!(", {limit} bytes of tables"),
                    format!(", {bytes} bytes"),
                ),
                None => (String::new(), String::new()),
            };
            let measured = find(rows, t.cpu, t.model, Operation::Estimate)
                .map_or("not measured".to_string(), |r| {
                    format!("{} at {}{measured_bytes}", r.mean, error(r))
                });
            format!(
                "{} on the {}, at most {} instructions at {:.0e}{target_bytes} ({measured})",
                t.model_name, t.cpu_name, t.instructions, t.error
            )
        })
        .collect();
    let missed = missed_targets(rows);
    format!(
        "Targets of the elliptic estimate (a full run fails over one; a test holds this \
         table to them): {}.{}\n",
        parts.join("; "),
        if missed.is_empty() {
            String::new()
        } else {
            format!(" **Missed**: {}.", missed.join("; "))
        }
    )
}

/// How many times fewer instructions `r` takes than the reference on its CPU.
fn fewer_instructions(rows: &[BenchRow], r: &BenchRow) -> String {
    rows.iter()
        .find(|x| {
            x.cpu == r.cpu && x.model == Model::Reference.name() && x.operation == r.operation
        })
        .filter(|_| r.model != Model::Reference.name())
        .map_or(String::from("-"), |x| {
            format!("{:.0}x", x.mean as f64 / r.mean.max(1) as f64)
        })
}

/// How many times more accurate a core's `r` is than Hamrock & Brewe.
fn more_accurate(rows: &[BenchRow], r: &BenchRow) -> String {
    let core = r.model == Model::F32.name() || r.model == Model::Fixed.name();
    let hb = rows.iter().find(|x| {
        x.cpu == r.cpu && x.model == Model::HamrockBrewe.name() && x.operation == r.operation
    });
    match (hb.and_then(|b| b.error), r.error) {
        (Some(b), Some(e)) if core && e > 0.0 => format!("{:.0}x", b / e),
        _ => String::from("-"),
    }
}

/// Bytes of table data (flash) that an operation reads, from the generated tables
/// themselves; `None` where it is code only or not ours (libm). Code sizes are in the
/// firmware's table (`cargo xtask firmware`).
fn table_bytes(model: Model, operation: Operation) -> Option<usize> {
    use misalign::fixed::tables as x;
    use misalign::float::tables as t;
    use std::mem::size_of_val as size;
    let force = size(&t::AXIAL_FORCE_LOW) + size(&t::AXIAL_FORCE_HIGH);
    // theta(g): its table and the finer one of its top octave.
    let theta_of_g = size(&t::THETA_OF_G_ROWS) + size(&t::THETA_OF_G_TOP);
    let log_exp = size(x::LOG2_MANTISSA.values) + size(x::EXP2_FRACTION.values);
    let log_g = size(x::LOG_G_LOW.values) + size(x::LOG_G_HIGH.values);
    let log_theta = size(x::LOG_THETA_LOW.values) + size(x::LOG_THETA_HIGH.values);
    use Operation as O;
    Some(match (model, operation) {
        (Model::F32, O::Estimate) => size(&t::G_OF_THETA_ROWS) + theta_of_g + force,
        (Model::F32, O::TableG) => size(&t::G_OF_THETA_ROWS),
        (Model::F32, O::TableThetaOfG) => theta_of_g,
        (Model::F32, O::KernelAxialForce) => force,
        (Model::F32, O::EstimateLine | O::KernelCbrt | O::KernelInvSqrt) => 0,
        (Model::F32, O::InverseMu) => size(&t::G_OF_THETA_ROWS) + force,
        (Model::F32, O::InversePhi) => size(&t::G_OF_THETA_ROWS) + theta_of_g + force,
        (Model::F32, O::InverseMuLine | O::InversePhiLine) => 0,
        (Model::Fixed, O::Estimate) => {
            log_exp + log_g + log_theta + size(x::LOG_FORCE_OVER_S.values)
        }
        (Model::Fixed, O::EstimateLine) => log_exp,
        (Model::Fixed, O::KernelLog2) => size(x::LOG2_MANTISSA.values),
        (Model::Fixed, O::KernelExp2) => size(x::EXP2_FRACTION.values),
        (Model::Fixed, O::TableLogG) => log_g,
        _ => return None,
    })
}

/// The cost table: per kernel and per core, error and instructions on the M0 and the
/// M4F, and the table bytes it reads.
pub fn cost(rows: &[BenchRow]) -> String {
    let mut s = String::new();
    writeln!(s, "| model | operation | max relative error | instructions on Cortex-M0 (mean / max) | instructions on Cortex-M4F (mean / max) | table bytes |").unwrap();
    writeln!(s, "|---|---|--:|--:|--:|--:|").unwrap();
    let mut seen = Vec::new();
    for r in rows {
        let (Some(model), Some(op)) = (
            Model::from_name(&r.model),
            Operation::from_name(&r.operation),
        ) else {
            continue;
        };
        // The monitor's profile has its own table (`stages`) and no error of its own.
        if (op.is_monitor() && op != Operation::Monitor) || seen.contains(&(model, op)) {
            continue;
        }
        seen.push((model, op));
        let on = |cpu: &str| find(rows, cpu, model, op).map_or("-".to_string(), counts);
        let bytes = table_bytes(model, op).map_or("-".to_string(), |b| b.to_string());
        writeln!(
            s,
            "| {} | `{}` | {} | {} | {} | {} |",
            r.model,
            r.operation,
            error(r),
            on("cortex-m0"),
            on("cortex-m4f"),
            bytes
        )
        .unwrap();
    }
    s
}

/// The monitor's stages table: per CPU and core, the monitor's whole per-sample
/// pipeline beside the bare estimate, and where the rest goes: a stage's cost is the
/// mean with it on minus the mean with it off, in the same run.
pub fn stages(rows: &[BenchRow]) -> String {
    let mut s = String::new();
    writeln!(s, "| cpu | core | monitor per sample (mean / max) | bare estimate (mean / max) | spike test | smoothing | trend | checks, states, wear, statistics, conversions |").unwrap();
    writeln!(s, "|---|---|--:|--:|--:|--:|--:|--:|").unwrap();
    for r in rows
        .iter()
        .filter(|r| r.operation == Operation::Monitor.name())
    {
        let Some(model) = Model::from_name(&r.model) else {
            continue;
        };
        let mean = |op| find(rows, &r.cpu, model, op).map(|x| x.mean as i64);
        let minus = |a: Option<i64>, b: Option<i64>| match (a, b) {
            (Some(a), Some(b)) => (a - b).to_string(),
            _ => "-".to_string(),
        };
        let all = Some(r.mean as i64);
        let bare = find(rows, &r.cpu, model, Operation::Estimate);
        writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            r.cpu,
            r.model,
            counts(r),
            bare.map_or("-".to_string(), counts),
            minus(all, mean(Operation::MonitorNoSpikes)),
            minus(all, mean(Operation::MonitorNoSmoothing)),
            minus(all, mean(Operation::MonitorNoTrend)),
            minus(mean(Operation::MonitorBare), bare.map(|b| b.mean as i64)),
        )
        .unwrap();
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::records;

    fn row(cpu: &str, model: Model, mean: u64, error: f64) -> BenchRow {
        BenchRow {
            cpu: cpu.into(),
            model: model.name().into(),
            operation: Operation::Estimate.name().into(),
            mean,
            max: mean + 20,
            error: Some(error),
        }
    }

    /// The committed figures (docs/bench.csv, from a full run) meet the estimate's
    /// targets.
    #[test]
    fn committed_estimates_meet_their_targets() {
        let rows = records::read::<BenchRow>().unwrap();
        assert_eq!(missed_targets(&rows), Vec::<String>::new());
    }

    /// One instruction or one error above a target, or a target's row missing, is a
    /// miss; the figures at the targets are not.
    #[test]
    fn a_target_is_missed_by_one_instruction_or_a_larger_error() {
        let at = [
            row("cortex-m4f", Model::F32, 100, 5e-7),
            row("cortex-m0", Model::Fixed, 350, 1e-5),
        ];
        assert_eq!(missed_targets(&at), Vec::<String>::new());
        let over = [
            row("cortex-m4f", Model::F32, 101, 5e-7),
            row("cortex-m0", Model::Fixed, 350, 2e-5),
        ];
        let missed = missed_targets(&over);
        assert_eq!(missed.len(), 2, "{missed:?}");
        assert!(
            missed[0].contains("101 instructions, target 100"),
            "{missed:?}"
        );
        assert!(missed[1].contains("error 2.0e-5"), "{missed:?}");
        assert_eq!(missed_targets(&at[..1]).len(), 1);
        assert!(targets_note(&over).contains("**Missed**"));
    }
}
