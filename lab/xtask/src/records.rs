//! The measurements' CSV files under `docs/`, one row type per file. The command that
//! measures writes its file; `cargo xtask measurements` and `cargo xtask figures` read
//! them back, so every table and figure of docs/measurements.md is regenerable from
//! what is committed.
//!
//! Columns are read by name (in any order); a float the tables print is stored as it
//! is printed from (four significant digits), so that a table written straight after a
//! measurement equals the one regenerated from its CSV.

use std::path::PathBuf;

/// A row of one of the CSV files.
pub trait Record: Sized {
    /// The file's name under `docs/`.
    const FILE: &'static str;
    /// Its columns, in the order written.
    const COLUMNS: &'static [&'static str];
    /// The row's fields, in the order of [`Record::COLUMNS`].
    fn fields(&self) -> Vec<String>;
    /// The row from a record of the file.
    fn parse(r: &Fields) -> Result<Self, String>;
}

/// A field's value in a CSV file.
pub trait Column: Sized {
    fn write(&self) -> String;
    fn read(s: &str) -> Result<Self, String>;
}

impl Column for String {
    fn write(&self) -> String {
        self.clone()
    }
    fn read(s: &str) -> Result<Self, String> {
        Ok(s.to_string())
    }
}

macro_rules! parsed_column {
    ($($t:ty),*) => {$(
        impl Column for $t {
            fn write(&self) -> String {
                self.to_string()
            }
            fn read(s: &str) -> Result<Self, String> {
                s.parse().map_err(|_| format!("`{s}` is not a number"))
            }
        }
    )*};
}
parsed_column!(u32, u64);

/// A float in full (the shortest form that reads back to it): an integer as one
/// (`48`), else in exponent form (`3.194e-7`).
impl Column for f64 {
    fn write(&self) -> String {
        if self.fract() == 0.0 && self.abs() < 1e15 {
            format!("{self}")
        } else {
            format!("{self:e}")
        }
    }
    fn read(s: &str) -> Result<Self, String> {
        s.parse().map_err(|_| format!("`{s}` is not a number"))
    }
}

/// A float that may be missing (not measured): an empty field.
impl Column for Option<f64> {
    fn write(&self) -> String {
        self.map_or(String::new(), |x| x.write())
    }
    fn read(s: &str) -> Result<Self, String> {
        if s.is_empty() {
            Ok(None)
        } else {
            f64::read(s).map(Some)
        }
    }
}

/// Defines a CSV row type: its fields, each with its column, and its file.
macro_rules! record {
    ($(#[$doc:meta])* $row:ident in $file:literal {
        $($(#[$fdoc:meta])* $field:ident: $t:ty = $column:literal,)*
    }) => {
        $(#[$doc])*
        #[derive(Debug, Clone, PartialEq)]
        pub struct $row {
            $($(#[$fdoc])* pub $field: $t,)*
        }

        impl Record for $row {
            const FILE: &'static str = $file;
            const COLUMNS: &'static [&'static str] = &[$($column),*];
            fn fields(&self) -> Vec<String> {
                vec![$(Column::write(&self.$field)),*]
            }
            fn parse(r: &Fields) -> Result<Self, String> {
                Ok($row {
                    $($field: <$t as Column>::read(r.str($column)?)
                        .map_err(|e| format!("line {}, `{}`: {e}", r.line, $column))?,)*
                })
            }
        }
    };
}

/// One record of a CSV file, its fields by column name.
pub struct Fields<'a> {
    columns: Vec<Option<usize>>,
    record: &'a csv::StringRecord,
    names: &'static [&'static str],
    line: usize,
}

impl Fields<'_> {
    /// The field of `column` (one of the row type's columns).
    pub fn str(&self, column: &str) -> Result<&str, String> {
        let i = self
            .names
            .iter()
            .position(|n| *n == column)
            .and_then(|i| self.columns[i])
            .ok_or_else(|| format!("no column `{column}`"))?;
        self.record
            .get(i)
            .ok_or_else(|| format!("line {}: too few fields", self.line))
    }
}

/// `x` to four significant digits, as the CSV files keep a measured error: a table
/// printed straight after a measurement is then the one redrawn from its CSV.
pub fn rounded(x: f64) -> f64 {
    format!("{x:.3e}").parse().unwrap_or(x)
}

/// The CSV text of `rows`.
pub fn to_csv<R: Record>(rows: &[R]) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let write = |w: &mut csv::Writer<Vec<u8>>, f: &[String]| {
        w.write_record(f).expect("CSV to memory");
    };
    write(
        &mut w,
        &R::COLUMNS.iter().map(|c| c.to_string()).collect::<Vec<_>>(),
    );
    for r in rows {
        write(&mut w, &r.fields());
    }
    String::from_utf8(w.into_inner().expect("CSV to memory")).expect("UTF-8 fields")
}

/// The rows of a CSV text (`what` names it in errors).
pub fn parse<R: Record>(text: &str, what: &str) -> Result<Vec<R>, String> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let headers = reader
        .headers()
        .map_err(|e| format!("{what}: {e}"))?
        .clone();
    let columns: Vec<Option<usize>> = R::COLUMNS
        .iter()
        .map(|c| headers.iter().position(|h| h == *c))
        .collect();
    let mut rows = Vec::new();
    for (index, record) in reader.records().enumerate() {
        let record = record.map_err(|e| format!("{what}: {e}"))?;
        let fields = Fields {
            columns: columns.clone(),
            record: &record,
            names: R::COLUMNS,
            line: index + 2,
        };
        rows.push(R::parse(&fields).map_err(|e| format!("{what}: {e}"))?);
    }
    Ok(rows)
}

/// `docs/<file>`.
pub fn path<R: Record>() -> PathBuf {
    crate::root().join("docs").join(R::FILE)
}

/// The rows of the committed `docs/<file>`.
pub fn read<R: Record>() -> Result<Vec<R>, String> {
    let path = path::<R>();
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse(&text, &format!("docs/{}", R::FILE))
}

/// Writes `docs/<file>`.
pub fn write<R: Record>(rows: &[R]) -> Result<(), String> {
    let path = path::<R>();
    std::fs::write(&path, to_csv(rows)).map_err(|e| format!("{}: {e}", path.display()))?;
    eprintln!("wrote docs/{}", R::FILE);
    Ok(())
}

record! {
    /// docs/bench.csv (`cargo xtask bench`): per CPU, model and operation, instructions
    /// per call in QEMU and the worst relative error on the host.
    BenchRow in "bench.csv" {
        /// `cortex-m0`, ...
        cpu: String = "cpu",
        /// `reference`, `f32`, `fixed`, `hamrock-brewe`.
        model: String = "model",
        /// `estimate`, `table:g`, `kernel:cbrt`, `monitor:no_trend`, ...
        operation: String = "operation",
        /// Instructions per call, mean and maximum.
        mean: u64 = "instructions_mean",
        max: u64 = "instructions_max",
        /// Worst relative error against the reference; `None` where none is measured
        /// (the monitor's profile).
        error: Option<f64> = "max_rel_error",
    }
}

record! {
    /// docs/shapes.csv (`cargo xtask shapes`): one shape of one table on one core.
    ShapeRow in "shapes.csv" {
        /// `cortex-m4f`, ...
        cpu: String = "cpu",
        /// `g`, `theta_of_g`, `log_g`, `log_theta_of_g`.
        table: String = "table",
        /// `f32` or `fixed`.
        core: String = "core",
        /// `library` (the library's kernel, measured in the same run), `shipped` (the
        /// shape the library ships, generated and measured like every other) or
        /// `variant`.
        kind: String = "kind",
        /// `u-s1-d6`, `quad-4+32`, ...; `library` for the library's kernel.
        shape: String = "shape",
        /// `u`, `t` (f32) or `log2` (fixed point).
        variable: String = "variable",
        /// Segments per octave of the table's argument: `4`, or `4+32` for two tables.
        segments: String = "segments_per_octave",
        /// Polynomial degree per segment (fixed point: 1 linear, 2 quadratic).
        degree: u32 = "degree",
        /// Table data in flash.
        bytes: u64 = "bytes",
        /// Instructions per evaluation, mean and maximum.
        mean: f64 = "instructions_mean",
        max: f64 = "instructions_max",
        /// Worst relative error against the f64 reference.
        error: f64 = "max_rel_error",
    }
}

record! {
    /// docs/sweep.csv (`cargo xtask sweep --write`): one kernel over its whole domain.
    SweepRow in "sweep.csv" {
        kernel: String = "kernel",
        domain: String = "domain",
        points: u64 = "points",
        /// Worst error in ulps of the result (`log2_u32`: in units of 2^-24).
        max_ulps: f64 = "max_ulps",
        max_rel: f64 = "max_rel_error",
        /// The input of the worst relative error.
        at: f64 = "worst_at",
    }
}

record! {
    /// docs/firmware.csv (`cargo xtask firmware --write`): the estimator's minimal
    /// images on one core, or the monitoring node's (`model` starting with `node`).
    SizeRow in "firmware.csv" {
        /// `Cortex-M4F`, ...
        core: String = "core",
        /// `f32` or `fixed`.
        number: String = "number",
        model: String = "model",
        /// Bytes: the minimal image's flash and RAM (statics; the node's: and stack).
        image_flash: u64 = "image_flash",
        image_ram: u64 = "image_ram",
        /// The per-sample estimator's flash and the one-off preparation's (0: none).
        estimator_flash: u64 = "estimator_flash",
        preparation_flash: u64 = "preparation_flash",
        /// Deepest stack of one per-sample call (the node's: of its whole loop).
        stack: u64 = "stack",
        /// Instructions per sample over the firmware's trace (0: not measured).
        instructions_mean: u64 = "instructions_mean",
        instructions_max: u64 = "instructions_max",
    }
}

record! {
    /// docs/node.csv (`cargo xtask firmware --write`): the monitoring node
    /// (`nodes/firmware`) on one core, checked against the host's replay.
    NodeRow in "node.csv" {
        /// `Cortex-M4F`, ...
        core: String = "core",
        /// `f32` or `fixed`.
        number: String = "number",
        /// `scenario` (its samples straight) or `simulated sensors`.
        input: String = "input",
        /// Bytes: the image's flash, its statics, the deepest stack of its run, the
        /// board's RAM.
        flash: u64 = "flash",
        ram: u64 = "ram_statics",
        stack: u64 = "stack",
        board_ram: u64 = "board_ram",
        /// Samples processed and events logged.
        samples: u64 = "samples",
        events: u64 = "events",
        /// The largest difference from the host replay's values, as a share of the
        /// core's tolerance (0: bit for bit).
        worst: f64 = "worst_share_of_tolerance",
        /// Instructions per sample of `Monitor::process`, mean and maximum.
        instructions_mean: u64 = "instructions_mean",
        instructions_max: u64 = "instructions_max",
    }
}

record! {
    /// docs/pico.csv (`cargo xtask pico --measure`): the Pico node's image, its RAM
    /// and the deepest stack of a commissioned node's run in the emulator.
    PicoRow in "pico.csv" {
        /// The board.
        board: String = "board",
        /// Bytes: the image's flash, its statics, the deepest stack, the stack's
        /// reservation (memory.x), the board's RAM.
        flash: u64 = "flash",
        ram: u64 = "ram_statics",
        stack: u64 = "stack",
        stack_reserved: u64 = "stack_reserved",
        board_ram: u64 = "board_ram",
        /// Samples the node monitored in the run.
        samples: u64 = "samples",
    }
}

record! {
    /// docs/modbus-node.csv (`cargo xtask modbus --measure`): the Modbus node with its
    /// flash storage (`lab/harness/src/bin/modbus_flash_node.rs`) on one core: its
    /// program and the RAM it leaves free.
    ModbusNodeRow in "modbus-node.csv" {
        /// `Cortex-M0`, `Cortex-M4F`.
        core: String = "core",
        /// Bytes: the program (flash: vector table, code, read-only data, .data's
        /// values), the statics, the deepest stack of its run, the board's RAM.
        program: u64 = "program",
        ram: u64 = "ram_statics",
        stack: u64 = "stack",
        board_ram: u64 = "board_ram",
    }
}

record! {
    /// docs/accuracy.csv (`cargo xtask accuracy`): the worst relative error of one
    /// quantity of one model, over every row of the reference data for its contact.
    AccuracyRow in "accuracy.csv" {
        /// `f32`, `fixed`, `reference`.
        model: String = "model",
        /// `elliptic` or `line`.
        contact: String = "contact",
        /// The reference data's column: `s` (d/b), `F`, `phi0`, `m`, `n`, `a`, `b`, `p0`.
        quantity: String = "quantity",
        max_rel: f64 = "max_rel_error",
        /// Rows compared.
        rows: u64 = "rows",
    }
}

record! {
    /// docs/web.csv (`cargo xtask web --measure`): one measured quantity of the web
    /// console (tools/web).
    WebRow in "web.csv" {
        /// `download_wasm_gzip`, `download_script_gzip`, `ready`, `replay_rows`,
        /// `replay_page`, `replay_example`, `replay_longest_pause`,
        /// `idle_longest_pause`.
        quantity: String = "quantity",
        value: f64 = "value",
        /// `B`, `ms`, `rows`, `rows/s`.
        unit: String = "unit",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_read_back_by_column_name_and_quoted_fields_survive() {
        let rows = vec![BenchRow {
            cpu: "cortex-m0".into(),
            model: "f32".into(),
            operation: "monitor:bare".into(),
            mean: 10,
            max: 12,
            error: None,
        }];
        let text = to_csv(&rows);
        assert_eq!(
            text,
            "cpu,model,operation,instructions_mean,instructions_max,max_rel_error\n\
             cortex-m0,f32,monitor:bare,10,12,\n"
        );
        assert_eq!(parse::<BenchRow>(&text, "t").unwrap(), rows);
        let reordered = "max_rel_error,operation,model,cpu,instructions_max,instructions_mean\n\
                         1e-7,estimate,f32,cortex-m7,101,100\n";
        let r = parse::<BenchRow>(reordered, "t").unwrap();
        assert_eq!((r[0].mean, r[0].error), (100, Some(1e-7)));
        assert!(parse::<BenchRow>("cpu,model,operation\nm0,f32,estimate\n", "t").is_err());
        let bad = "cpu,model,operation,instructions_mean,instructions_max,max_rel_error\n\
                   m0,f32,estimate,abc,1,1e-7\n";
        assert!(parse::<BenchRow>(bad, "t").is_err());
        let sweep = vec![SweepRow {
            kernel: "table g(theta)".into(),
            domain: "theta in [2^-32, pi/2], every 2^12-th f32".into(),
            points: 3,
            max_ulps: 2.19,
            max_rel: 1.46e-7,
            at: 3.9787e-3,
        }];
        assert_eq!(parse::<SweepRow>(&to_csv(&sweep), "t").unwrap(), sweep);
    }
}
