//! The monitor example's input files (`cargo run --example monitor -- --scene ...
//! --trace ...`): the scene and a recorded trace (CSV), read by the estimator's rules
//! ([`crate::table`]: a repeated column is an error naming it, a `;`-separated file is
//! read so, a bad number's message names its column and row).
//!
//! A trace is read row by row ([`Trace`]), in memory that does not grow with its
//! length. A row the monitor can place in time but not read (a cell that is not a
//! number, not UTF-8, out of f64's range) becomes a sample with a NaN there, which the
//! monitor counts as a sensor fault; a row without a usable time (its `t` empty, not a
//! number or not finite; a field count other than the header's; an unterminated quote;
//! a line over [`MAX_LINE`] bytes) is skipped and counted. A time the monitor's clock
//! cannot represent ([`TraceClock`]) refuses the trace.

use crate::table::{self, LineSplitter};
use misalign::Scene;
use misalign::monitor::{FaultKind, Sample, SensorFault, SensorId};
use std::error::Error;
use std::io::{BufRead, Read};

type Res<T> = Result<T, Box<dyn Error>>;

/// The scene's columns.
const SCENE: [&str; 5] = ["R1", "R2", "G", "nu", "mu"];

/// The trace's columns; `V`, `F` and `fault` are optional.
const TRACE: [&str; 3] = ["t", "P", "phi"];

/// The longest row of a trace (bytes); a longer one is skipped.
pub const MAX_LINE: usize = 64 * 1024;

/// How many skipped or faulty rows are named in a report.
pub const NAMED_ROWS: usize = 5;

/// The scene: a CSV header naming `R1,R2,G,nu,mu` and optionally `length` (any order)
/// and one row.
pub fn read_scene(file: impl Read) -> Res<Scene> {
    Ok(scene_and_delimiter(file)?.0)
}

/// The scene and the file's delimiter (`;` when it is `;`-separated).
pub fn scene_and_delimiter(file: impl Read) -> Res<(Scene, u8)> {
    let mut data = Vec::new();
    file.take(1 << 20).read_to_end(&mut data)?;
    let (delimiter, header) = table::header(&data, &SCENE)?;
    let (at, optional) = table::find_columns(&header, &SCENE, &["length"])?;
    let mut reader = csv::ReaderBuilder::new()
        .delimiter(delimiter)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(&data[..]);
    reader.byte_headers()?;
    let row = reader
        .byte_records()
        .next()
        .ok_or("the scene file has no row")??;
    let line = row.position().map_or(2, |p| p.line());
    let at_row = |m: String| format!("row {line}: {m}");
    if let Some(m) = table::bad_record(&row, header.len()) {
        return Err(at_row(m).into());
    }
    let get = |k: usize| table::number(SCENE[k], row.get(at[k]).unwrap_or(b"")).map_err(at_row);
    let scene = Scene::new(get(0)?, get(1)?, get(2)?, get(3)?, get(4)?)
        .map_err(|e| at_row(e.to_string()))?;
    let scene = match optional[0].map(|i| row.get(i).unwrap_or(b"")) {
        Some(field) if !table::is_blank(field) => {
            let l = table::number("length", field).map_err(at_row)?;
            scene
                .with_length(l)
                .map_err(|e| at_row(format!("length: {e}")))?
        }
        _ => scene,
    };
    Ok((scene, delimiter))
}

/// A trace's times (s) as the node's free-running u32 ms counter, refusing what the
/// monitor would misread: a time beyond 2^53 ms (where f64 no longer tells ms apart,
/// and `as i64` would saturate), and a step of 2^31 ms (24.8 days) or more between
/// consecutive times, which the counter, taken modulo 2^32 ms, would turn into a
/// shorter step or a step back. Times that both lie in the counter's own range
/// (0 to 2^32 ms) are read as the counter itself, as the node reads it: a wrap is a
/// step forward, a larger step back a reset.
#[derive(Debug, Clone, Copy, Default)]
pub struct TraceClock {
    last_ms: Option<i64>,
}

/// 2^53 ms: beyond it, f64 seconds do not hold every millisecond.
const CLOCK_LIMIT_MS: f64 = 9_007_199_254_740_992.0;

/// The largest step (ms) the monitor's wrapping counter takes as it is.
const STEP_LIMIT_MS: i64 = (1 << 31) - 1;

impl TraceClock {
    /// A clock before the first time.
    pub fn new() -> Self {
        TraceClock::default()
    }

    /// `t` (s, finite) as the counter, or the message why the monitor cannot take it.
    pub fn time_ms(&mut self, t: f64) -> Result<u32, String> {
        if !t.is_finite() {
            return Err(format!("t = {t} s is not a time"));
        }
        let ms = t * 1e3;
        if ms.abs() > CLOCK_LIMIT_MS {
            // The smallest unit that brings t to at most 1e10 s (about 300 years).
            let (divisor, unit) = [(1e3, "ms"), (1e6, "us"), (1e9, "ns")]
                .into_iter()
                .find(|(d, _)| t.abs() / d <= 1e10)
                .unwrap_or((1e9, "ns"));
            return Err(format!(
                "t = {t:e} s is beyond the monitor's millisecond clock (exact up to 2^53 ms, \
                 {:.1e} s); is t in {unit} ({:e} s)?",
                CLOCK_LIMIT_MS / 1e3,
                t / divisor
            ));
        }
        // Exact: |ms| <= 2^53.
        let ms = ms.round() as i64;
        let counter = |ms: i64| (0..1 << 32).contains(&ms);
        if let Some(last) = self.last_ms
            && !(counter(last) && counter(ms))
        {
            let step = ms - last;
            if step.abs() > STEP_LIMIT_MS {
                return Err(format!(
                    "t steps {} by {:e} s ({:.1} days) from the previous time, beyond the \
                     2^31 ms (24.8 days) the monitor's wrapping u32 millisecond counter can \
                     step; is t in s (not ms, us or ns)? A pause that long: split the trace there",
                    if step > 0 { "forward" } else { "back" },
                    step.unsigned_abs() as f64 / 1e3,
                    step.unsigned_abs() as f64 / 8.64e7
                ));
            }
        }
        self.last_ms = Some(ms);
        Ok(ms.rem_euclid(1 << 32) as u32)
    }
}

/// Rows counted for a report: how many, and the first [`NAMED_ROWS`] with why.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tally {
    /// How many rows.
    pub count: u64,
    /// The first rows: (row number, header = 1; why).
    pub first: Vec<(u64, String)>,
}

impl Tally {
    fn note(&mut self, row: u64, why: impl FnOnce() -> String) {
        self.count += 1;
        if self.first.len() < NAMED_ROWS {
            self.first.push((row, why()));
        }
    }

    /// `"3 (row 5: t: not a number: \"x\"; row 9: ...)"`, or `"0"`.
    pub fn describe(&self) -> String {
        if self.count == 0 {
            return "0".into();
        }
        let rows: Vec<String> = self
            .first
            .iter()
            .map(|(row, why)| format!("row {row}: {why}"))
            .collect();
        let more = if self.count > self.first.len() as u64 {
            "; ..."
        } else {
            ""
        };
        format!("{} ({}{more})", self.count, rows.join("; "))
    }
}

/// A trace read row by row: columns `t` (s), `P` (N), `phi` (rad), optional `V` (m/s)
/// and `F` (N), in any order. Each item is a sample, or the message (naming the row)
/// why the monitor cannot take the trace, after which the iteration ends. An empty `V`
/// or `F` cell is "not measured" (nominal speed, estimated F).
#[derive(Debug)]
pub struct Trace<R> {
    input: R,
    delimiter: u8,
    fields: usize,
    columns: [usize; 3],
    speed: Option<usize>,
    force: Option<usize>,
    fault: Option<usize>,
    split: LineSplitter,
    line: Vec<u8>,
    row: u64,
    clock: TraceClock,
    skipped: Tally,
    unreadable: Tally,
    done: bool,
}

impl<R: BufRead> Trace<R> {
    /// Reads the header: `Err` when it lacks a column or repeats one.
    pub fn new(mut input: R) -> Res<Self> {
        let mut line = Vec::new();
        (&mut input)
            .take(MAX_LINE as u64)
            .read_until(b'\n', &mut line)?;
        let (delimiter, header) = table::header(&line, &TRACE)?;
        let (at, optional) = table::find_columns(&header, &TRACE, &["V", "F", "fault"])?;
        Ok(Trace {
            input,
            delimiter,
            fields: header.len(),
            columns: [at[0], at[1], at[2]],
            speed: optional[0],
            force: optional[1],
            fault: optional[2],
            split: LineSplitter::new(delimiter),
            line,
            row: 1,
            clock: TraceClock::new(),
            skipped: Tally::default(),
            unreadable: Tally::default(),
            done: false,
        })
    }

    /// The delimiter: `;` when the trace is `;`-separated.
    pub fn delimiter(&self) -> u8 {
        self.delimiter
    }

    /// The rows skipped so far for want of a usable time.
    pub fn skipped(&self) -> &Tally {
        &self.skipped
    }

    /// The rows so far with a time but a cell that is not a number (sensor faults).
    pub fn unreadable(&self) -> &Tally {
        &self.unreadable
    }

    /// The next line into `self.line` (without its end); `Ok(false)` at the end.
    fn next_line(&mut self) -> std::io::Result<bool> {
        self.line.clear();
        let n = (&mut self.input)
            .take(MAX_LINE as u64 + 1)
            .read_until(b'\n', &mut self.line)?;
        if n == 0 {
            return Ok(false);
        }
        self.row += 1;
        if self.line.last() == Some(&b'\n') {
            self.line.pop();
        } else if self.line.len() > MAX_LINE {
            // The rest of an over-long line, dropped in the reader's own buffer.
            loop {
                let buf = self.input.fill_buf()?;
                if buf.is_empty() {
                    break;
                }
                let (used, end) = match buf.iter().position(|&b| b == b'\n') {
                    Some(i) => (i + 1, true),
                    None => (buf.len(), false),
                };
                self.input.consume(used);
                if end {
                    break;
                }
            }
        }
        if self.line.last() == Some(&b'\r') {
            self.line.pop();
        }
        Ok(true)
    }

    /// The sample of the line read, `Ok(None)` when it is skipped.
    fn sample(&mut self) -> Result<Option<Sample>, String> {
        let row = self.row;
        if table::is_blank(&self.line) {
            return Ok(None);
        }
        if self.line.len() > MAX_LINE {
            self.skipped
                .note(row, || format!("longer than {MAX_LINE} bytes"));
            return Ok(None);
        }
        if let Err(m) = self.split.split(&self.line) {
            self.skipped.note(row, || m);
            return Ok(None);
        }
        if self.split.len() != self.fields {
            let (got, want) = (self.split.len(), self.fields);
            self.skipped
                .note(row, || format!("{got} fields, the header {want}"));
            return Ok(None);
        }
        let [t, p, phi] = self.columns;
        let time = match table::number("t", self.split.field(t)) {
            Ok(t) if t.is_finite() => t,
            Ok(t) => {
                self.skipped.note(row, || format!("t = {t} is not a time"));
                return Ok(None);
            }
            Err(m) => {
                self.skipped.note(row, || m);
                return Ok(None);
            }
        };
        let time_ms = self
            .clock
            .time_ms(time)
            .map_err(|m| format!("row {row}: {m}"))?;
        let mut why = None;
        let mut value = |name: &str, j: usize| {
            table::number(name, self.split.field(j)).unwrap_or_else(|m| {
                why.get_or_insert(m);
                f64::NAN
            }) as f32
        };
        let mut sample = Sample::new(time_ms, value("P", p), value("phi", phi));
        for (column, name, cell) in [
            (self.speed, "V", &mut sample.speed),
            (self.force, "F", &mut sample.axial_force),
        ] {
            // An empty cell of an optional column: not measured this time.
            *cell = column
                .filter(|&j| !table::is_blank(self.split.field(j)))
                .map(|j| value(name, j));
        }
        let fault = self.fault.map(|j| self.split.field(j));
        match fault.filter(|f| !table::is_blank(f)).map(sensor_fault) {
            Some(Some(f)) => sample.sensor_fault = Some(f),
            Some(None) => {
                // Not a fault this reader knows: the row's values are not measurements.
                why.get_or_insert_with(|| "fault: not `sensor:kind`".into());
                sample.load = f32::NAN;
            }
            None => {}
        }
        if let Some(m) = why {
            self.unreadable.note(row, || m);
        }
        Ok(Some(sample))
    }
}

/// A sensor's own fault as a trace's optional `fault` column holds it: the sensor
/// (`load`, `probe1`, `probe2`, `speed`), a colon and the kind (`disconnected`, `bus`,
/// `saturated`, `stuck`, `jump`, `out_of_range`), as a node's sensors report it (the
/// Pico node's samples, `cargo xtask pico --samples`); `None` for anything else.
pub fn sensor_fault(cell: &[u8]) -> Option<SensorFault> {
    let text = std::str::from_utf8(cell).ok()?.trim();
    let (sensor, kind) = text.split_once(':')?;
    let sensor = SensorId::ALL.into_iter().find(|s| s.name() == sensor)?;
    let kind = FaultKind::ALL
        .into_iter()
        .find(|k| fault_kind_name(*k) == kind)?;
    Some(SensorFault { sensor, kind })
}

/// A fault kind's name in a trace's `fault` column.
pub fn fault_kind_name(kind: FaultKind) -> &'static str {
    match kind {
        FaultKind::Disconnected => "disconnected",
        FaultKind::Bus => "bus",
        FaultKind::Saturated => "saturated",
        FaultKind::Stuck => "stuck",
        FaultKind::Jump => "jump",
        FaultKind::OutOfRange => "out_of_range",
        _ => "unknown",
    }
}

impl<R: BufRead> Iterator for Trace<R> {
    type Item = Result<Sample, String>;

    fn next(&mut self) -> Option<Self::Item> {
        while !self.done {
            match self.next_line() {
                Ok(false) => self.done = true,
                Ok(true) => match self.sample() {
                    Ok(Some(s)) => return Some(Ok(s)),
                    Ok(None) => {}
                    Err(m) => {
                        self.done = true;
                        return Some(Err(m));
                    }
                },
                Err(e) => {
                    self.done = true;
                    return Some(Err(format!("row {}: {e}", self.row + 1)));
                }
            }
        }
        None
    }
}

/// A whole trace's samples (skipped rows left out), or the first message why the
/// monitor cannot take it.
pub fn read_trace(file: impl Read) -> Res<Vec<Sample>> {
    let trace = Trace::new(std::io::BufReader::new(file))?;
    Ok(trace.collect::<Result<Vec<_>, _>>()?)
}
