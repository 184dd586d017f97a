//! The firmware's size and node tables (docs/firmware.csv, docs/node.csv), with the
//! budget and targets they are held to.

use crate::records::{NodeRow, SizeRow};
use std::fmt::Write as _;

/// Per-sample estimator budget: flash (code + tables) and stack, in bytes. Applied to
/// the cores whose images are measured (`Cpu::sizes`); lower them when the estimator
/// beats them.
pub const FLASH_BUDGET: u64 = 8 * 1024;
pub const STACK_BUDGET: u64 = 256;

/// The monitoring node's targets on the Cortex-M0: flash and RAM (statics
/// and stack), in bytes. Reported (marked when over), not yet a failure.
pub const NODE_FLASH_TARGET: u64 = 16 * 1024;
pub const NODE_RAM_TARGET: u64 = 4 * 1024;

/// The node table (markdown, docs/measurements.md), and a failure where statics and
/// stack overflow the board's RAM.
pub fn node_table(rows: &[NodeRow]) -> (String, Vec<String>) {
    let mut t = String::from(
        "| core | number | input | flash | RAM: statics + stack | events as the host's | instructions per sample mean / max |\n\
         |---|---|---|--:|--:|--:|--:|\n",
    );
    let mut over = Vec::new();
    for r in rows {
        let total = r.ram + r.stack;
        let fits = total <= r.board_ram;
        writeln!(
            t,
            "| {} | {} | {} | {} | {} + {} = {}{} | {}, values {} | {} / {} |",
            r.core,
            r.number,
            r.input,
            r.flash,
            r.ram,
            r.stack,
            total,
            if fits {
                ""
            } else {
                " **over the board's RAM**"
            },
            r.events,
            if r.worst == 0.0 {
                "bit for bit".to_string()
            } else {
                format!("within {:.2} of the tolerance", r.worst)
            },
            r.instructions_mean,
            r.instructions_max
        )
        .unwrap();
        if !fits {
            over.push(format!(
                "{} node: {} B of statics and {} B of stack exceed the board's {} B of RAM",
                r.core, r.ram, r.stack, r.board_ram
            ));
        }
    }
    (t, over)
}

/// The size table's row of the monitoring node's minimal image.
pub const NODE_MODEL: &str = "node: monitor + elliptic, build-time scene, defmt";

/// The size and stack table (markdown, docs/measurements.md), and the budget failures.
pub fn table(rows: &[SizeRow]) -> (String, Vec<String>) {
    let mut t = String::from(
        "| core | number | model | image flash | image RAM | estimator flash | preparation | estimator stack | instructions mean / max |\n\
         |---|---|---|--:|--:|--:|--:|--:|--:|\n",
    );
    let mut over = Vec::new();
    for r in rows {
        if r.model == NODE_MODEL {
            node_line(&mut t, r);
            continue;
        }
        let flash_over = r.estimator_flash > FLASH_BUDGET;
        let stack_over = r.stack > STACK_BUDGET;
        let mark = |over: bool| if over { " **over budget**" } else { "" };
        writeln!(
            t,
            "| {} | {} | {} | {} | {} | {}{} | {} | {}{} | {} / {} |",
            r.core,
            r.number,
            r.model,
            r.image_flash,
            r.image_ram,
            r.estimator_flash,
            mark(flash_over),
            r.preparation_flash,
            r.stack,
            mark(stack_over),
            r.instructions_mean,
            r.instructions_max
        )
        .unwrap();
        if flash_over || stack_over {
            over.push(format!(
                "{} {} estimator over budget: {} B flash (budget {FLASH_BUDGET}), {} B stack (budget {STACK_BUDGET})",
                r.core, r.model, r.estimator_flash, r.stack
            ));
        }
    }
    (t, over)
}

/// The node's row: its image and its whole RAM (statics and stack), marked where the
/// Cortex-M0's targets are missed; no per-sample columns.
fn node_line(t: &mut String, r: &SizeRow) {
    let m0 = r.core == "Cortex-M0";
    let mark = |over: bool| if m0 && over { " **over target**" } else { "" };
    writeln!(
        t,
        "| {} | {} | {} | {}{} | {}{} | – | – | {} | – |",
        r.core,
        r.number,
        r.model,
        r.image_flash,
        mark(r.image_flash > NODE_FLASH_TARGET),
        r.image_ram,
        mark(r.image_ram > NODE_RAM_TARGET),
        r.stack,
    )
    .unwrap();
}
