//! `cargo xtask measurements [--check]`: every table of docs/measurements.md, and the
//! README's headline, drawn from the committed CSVs under `docs/` (each measuring
//! command writes its CSV and then calls [`update`]; the tables are drawn here, from
//! the CSVs alone, never by the commands' modules). `--check` fails if a committed
//! table differs from what the CSVs draw, as `cargo xtask figures --check` does for the
//! SVGs; a unit test does the same under `cargo test`.
//!
//! Each table sits between `<!-- NAME:begin -->` and `<!-- NAME:end -->`; the prose
//! around it is the page's own and carries no measured number.

pub mod accuracy;
pub mod bench;
pub mod firmware;
pub mod shapes;
pub mod sweep;
pub mod web;

use crate::records::{
    self, AccuracyRow, BenchRow, ModbusNodeRow, NodeRow, PicoRow, ShapeRow, SizeRow, SweepRow,
    WebRow,
};
use bench::find;
use misalign_workload::{Model, Operation};
use std::fmt::Write as _;
use std::process::ExitCode;

/// The measurements page, from the repository's root.
pub const PAGE: &str = "docs/measurements.md";
const README: &str = "README.md";

/// One generated table: the file it is in, its markers' name, its text.
struct Block {
    file: &'static str,
    name: &'static str,
    text: String,
}

/// Every table, drawn from the committed CSVs.
fn blocks() -> Result<Vec<Block>, String> {
    let bench = records::read::<BenchRow>()?;
    let shapes = records::read::<ShapeRow>()?;
    let sweep = records::read::<SweepRow>()?;
    let sizes = records::read::<SizeRow>()?;
    let nodes = records::read::<NodeRow>()?;
    let accuracy = records::read::<AccuracyRow>()?;
    let pico = records::read::<PicoRow>()?;
    let modbus_node = records::read::<ModbusNodeRow>()?;
    let web = records::read::<WebRow>()?;
    let block = |file, name, text| Block { file, name, text };
    Ok(vec![
        block(README, "headline", headline(&bench, &accuracy)),
        block(PAGE, "accuracy", accuracy::table(&accuracy)),
        block(
            PAGE,
            "bench",
            format!(
                "{}\n{}",
                bench::estimates(&bench),
                bench::targets_note(&bench)
            ),
        ),
        block(PAGE, "cost", bench::cost(&bench)),
        block(PAGE, "stages", bench::stages(&bench)),
        block(PAGE, "shapes", shapes::table(&shapes)),
        block(PAGE, "sweep", sweep::markdown(&sweep, false)),
        block(PAGE, "firmware", sizes_block(&sizes)),
        block(PAGE, "node", node(&nodes)),
        block(PAGE, "modbus-node", modbus_node_table(&modbus_node)),
        block(PAGE, "pico", pico_table(&pico)),
        block(PAGE, "web", web::table(&web)?),
    ])
}

/// The README's headline: per model, the worst error of d/b (docs/accuracy.csv), the
/// instructions per estimate and the monitor's per sample on the Cortex-M0 and M4F
/// (docs/bench.csv).
fn headline(bench: &[BenchRow], accuracy: &[AccuracyRow]) -> String {
    let mut s = String::from(
        "| model | max relative error of d/b | instructions per estimate: Cortex-M0 / M4F | monitor per sample: Cortex-M0 / M4F |\n\
         |---|--:|--:|--:|\n",
    );
    let mean = |cpu, model, op| find(bench, cpu, model, op).map(|r| r.mean);
    for (model, name) in [
        (Model::F32, "f32 core"),
        (Model::Fixed, "fixed-point core"),
        (Model::Reference, "f64 reference"),
    ] {
        let error = accuracy
            .iter()
            .find(|r| r.model == model.name() && r.contact == "elliptic" && r.quantity == "s")
            .map_or("-".into(), |r| format!("{:.1e}", r.max_rel));
        let both = |op| match (mean("cortex-m0", model, op), mean("cortex-m4f", model, op)) {
            (None, None) => "-".to_string(),
            (m0, m4f) => {
                let n = |x: Option<u64>| x.map_or("-".into(), |x| x.to_string());
                format!("{} / {}", n(m0), n(m4f))
            }
        };
        writeln!(
            s,
            "| {name} | {error} | {} | {} |",
            both(Operation::Estimate),
            both(Operation::Monitor)
        )
        .unwrap();
    }
    s.push_str(
        "\nElliptic contact; instructions are means in QEMU (`-icount`: instructions, not \
         cycles); errors against independent reference data. How each is measured, and \
         every other table: [docs/measurements.md](docs/measurements.md).\n",
    );
    s
}

/// The size table, with the budget and targets it is held to (`firmware.rs`).
fn sizes_block(rows: &[SizeRow]) -> String {
    use firmware::{FLASH_BUDGET, NODE_FLASH_TARGET, NODE_RAM_TARGET, STACK_BUDGET};
    format!(
        "{}\nBudget of the per-sample estimator (the command fails over it): {FLASH_BUDGET} B \
         of flash and {STACK_BUDGET} B of stack. Targets of the node on the Cortex-M0 \
         (marked when missed): {NODE_FLASH_TARGET} B of flash, {NODE_RAM_TARGET} B of RAM.\n",
        firmware::table(rows).0
    )
}

/// The node table and the scenario's length it was measured over.
fn node(rows: &[NodeRow]) -> String {
    let (table, _) = firmware::node_table(rows);
    let samples: Vec<u64> = rows.iter().map(|r| r.samples).collect();
    match samples.first() {
        Some(n) if samples.iter().all(|x| x == n) => {
            format!("{table}\nEach run: the scenario's {n} samples.\n")
        }
        _ => table,
    }
}

/// The Modbus node with flash (docs/modbus-node.csv): its program and the RAM it leaves
/// free, against the Cortex-M0's targets (`crate::modbus`).
fn modbus_node_table(rows: &[ModbusNodeRow]) -> String {
    use crate::modbus::{M0_PROGRAM_TARGET, M0_RAM_FREE_TARGET};
    let mut s = String::from(
        "| core | program | RAM: statics + deepest stack | left free of the board's RAM |\n\
         |---|--:|--:|--:|\n",
    );
    for r in rows {
        let used = r.ram + r.stack;
        let free = r.board_ram as i64 - used as i64;
        let m0 = r.core == "Cortex-M0";
        let mark = |missed: bool| if m0 && missed { " **over target**" } else { "" };
        writeln!(
            s,
            "| {} | {}{} | {} + {} = {used} | {free} of {}{} |",
            r.core,
            r.program,
            mark(r.program > M0_PROGRAM_TARGET),
            r.ram,
            r.stack,
            r.board_ram,
            mark(free < M0_RAM_FREE_TARGET as i64)
        )
        .unwrap();
    }
    write!(
        s,
        "\nTargets of the Cortex-M0 node with flash (the micro:bit's 16 KiB of RAM; a 64 KiB \
         part keeping 16 KiB of its flash for the storage): a program of at most {M0_PROGRAM_TARGET} B \
         and at least {M0_RAM_FREE_TARGET} B of RAM left free. `cargo xtask modbus --measure` \
         fails when one is missed, after writing what it measured.\n"
    )
    .unwrap();
    s
}

/// The Pico node's table (docs/pico.csv).
fn pico_table(rows: &[PicoRow]) -> String {
    let mut s = String::from(
        "| board | flash | RAM: statics + deepest stack | stack reserved | of the board's RAM | samples monitored |\n\
         |---|--:|--:|--:|--:|--:|\n",
    );
    for r in rows {
        writeln!(
            s,
            "| {} | {} | {} + {} = {} | {} | {} | {} |",
            r.board,
            r.flash,
            r.ram,
            r.stack,
            r.ram + r.stack,
            r.stack_reserved,
            r.board_ram,
            r.samples
        )
        .unwrap();
    }
    write!(
        s,
        "\nThe stack's reservation (nodes/pico/memory.x, below the statics: an overflow \
         faults instead of writing over them) keeps at least {} B above the deepest stack \
         (`cargo xtask pico --measure` fails otherwise).\n",
        crate::pico::STACK_HEADROOM
    )
    .unwrap();
    s
}

/// `text` with the block between the markers `<!-- NAME:begin -->` and
/// `<!-- NAME:end -->` replaced by `block`.
fn replace(text: &str, name: &str, block: &str) -> Result<String, String> {
    let (begin, end) = (
        format!("<!-- {name}:begin -->"),
        format!("<!-- {name}:end -->"),
    );
    let (Some(a), Some(b)) = (text.find(&begin), text.find(&end)) else {
        return Err(format!("no {name} markers"));
    };
    if b < a {
        return Err(format!("the {name} markers are out of order"));
    }
    Ok(format!("{}{begin}\n{block}{}", &text[..a], &text[b..]))
}

/// Each file with its tables as the CSVs draw them: `(path, committed, drawn)`.
fn drawn() -> Result<Vec<(&'static str, String, String)>, String> {
    let blocks = blocks()?;
    let mut out = Vec::new();
    for file in [PAGE, README] {
        let path = crate::root().join(file);
        let committed = std::fs::read_to_string(&path).map_err(|e| format!("{file}: {e}"))?;
        let mut text = committed.clone();
        for b in blocks.iter().filter(|b| b.file == file) {
            text = replace(&text, b.name, &b.text).map_err(|e| format!("{file}: {e}"))?;
        }
        out.push((file, committed, text));
    }
    Ok(out)
}

/// The files whose tables differ from what the committed CSVs draw.
pub fn stale() -> Result<Vec<&'static str>, String> {
    Ok(drawn()?
        .into_iter()
        .filter(|(_, committed, text)| committed != text)
        .map(|(file, _, _)| file)
        .collect())
}

/// Writes every table from the committed CSVs.
pub fn update() -> Result<(), String> {
    for (file, committed, text) in drawn()? {
        if committed != text {
            std::fs::write(crate::root().join(file), text).map_err(|e| format!("{file}: {e}"))?;
            eprintln!("wrote the tables of {file}");
        }
    }
    Ok(())
}

/// `cargo xtask measurements [--check]`.
pub fn run(check: bool) -> ExitCode {
    let result = if check {
        stale().map(|files| {
            for f in &files {
                eprintln!("{f}: a table differs from its CSV: run `cargo xtask measurements`");
            }
            if files.is_empty() {
                println!("every table of {PAGE} and {README} is what its CSV draws");
            }
            files.is_empty()
        })
    } else {
        update().map(|()| true)
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("xtask measurements: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The committed tables are what the committed CSVs draw.
    #[test]
    fn committed_tables_match_their_csvs() {
        assert_eq!(
            stale().unwrap(),
            Vec::<&str>::new(),
            "run `cargo xtask measurements`"
        );
    }

    /// The headline takes the elliptic d/b error from the accuracy rows and the means
    /// of the estimate and the monitor on the Cortex-M0 and M4F from the bench rows.
    #[test]
    fn the_headline_reads_its_figures_from_the_rows() {
        let bench = |cpu: &str, model: &str, operation: &str, mean| BenchRow {
            cpu: cpu.into(),
            model: model.into(),
            operation: operation.into(),
            mean,
            max: mean + 1,
            error: Some(1.0),
        };
        let rows = [
            bench("cortex-m0", "f32", "estimate", 11),
            bench("cortex-m4f", "f32", "estimate", 12),
            bench("cortex-m3", "f32", "estimate", 13),
            bench("cortex-m0", "f32", "monitor", 21),
            bench("cortex-m4f", "f32", "monitor", 22),
            bench("cortex-m0", "fixed", "estimate", 31),
        ];
        let accuracy = |contact: &str, quantity: &str, max_rel| AccuracyRow {
            model: "f32".into(),
            contact: contact.into(),
            quantity: quantity.into(),
            max_rel,
            rows: 1,
        };
        let errors = [
            accuracy("line", "s", 5e-9),
            accuracy("elliptic", "F", 6e-9),
            accuracy("elliptic", "s", 7e-9),
        ];
        let h = headline(&rows, &errors);
        assert!(
            h.contains("| f32 core | 7.0e-9 | 11 / 12 | 21 / 22 |"),
            "{h}"
        );
        assert!(h.contains("| fixed-point core | - | 31 / - | - |"), "{h}");
        assert!(h.contains("| f64 reference | - | - | - |"), "{h}");
    }

    #[test]
    fn a_block_is_replaced_between_its_markers() {
        let text = "a\n<!-- t:begin -->\nold\n<!-- t:end -->\nb\n";
        assert_eq!(
            replace(text, "t", "new\n").unwrap(),
            "a\n<!-- t:begin -->\nnew\n<!-- t:end -->\nb\n"
        );
        assert!(replace(text, "u", "x").is_err());
        assert!(replace("<!-- t:end --><!-- t:begin -->", "t", "x").is_err());
    }
}
