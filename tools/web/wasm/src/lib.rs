//! The web console's binding: `misalign` and `misalign-cli` compiled to
//! `wasm32-unknown-unknown` behind wasm-bindgen, for the page in `tools/web/`. Every
//! answer is the PC tools' own code: the monitor's replay and its `--events` and
//! `--thresholds` files (`misalign_cli::replay`, `monitor_output`), the CSV estimator
//! and its inverses (`misalign_cli::estimate::run`, the example's arguments), scenes
//! prepared for a node (`misalign_cli::prepare`, as `examples/prepare.rs`), and a
//! node in the page (`misalign::modbus::Server`, [`node`]). This file only moves bytes
//! and text across; the functions without wasm-bindgen types are the host tests'.

mod json;
pub mod node;
pub mod plot;

use misalign::Scene;
use misalign::monitor::{Config, RiskState, scenario};
use misalign_cli::monitor_input;
use misalign_cli::monitor_output::{self as output, EventsWriter};
use misalign_cli::replay::{self, Model, Replay, Samples, Survey};
use std::cell::Cell;
use std::io::{BufRead, BufReader, Read};
use std::rc::Rc;
use wasm_bindgen::prelude::*;

/// A message for the page.
type Res<T> = Result<T, String>;

/// The scene of a scene file's text (the monitor example's `--scene` format); none or
/// blank: the built-in scenario's (the demo rollers).
pub fn scene_of(text: Option<&str>) -> Res<Scene> {
    match text.filter(|t| !t.trim().is_empty()) {
        Some(t) => monitor_input::read_scene(t.as_bytes()).map_err(|e| format!("scene: {e}")),
        None => scenario::scene().map_err(|e| format!("scene: {e}")),
    }
}

/// The samples of a trace's bytes (the monitor example's `--trace` format); none: the
/// built-in scenario.
fn samples<R: BufRead>(trace: Option<R>) -> Res<Samples<R>> {
    match trace {
        Some(r) => Samples::trace(r).map_err(|e| format!("trace: {e}")),
        None => Ok(Samples::builtin()),
    }
}

/// What a replay gives the page: the `--events` file, the planner's table (when
/// asked), the summary (JSON) and the plot's bins.
pub struct Reviewed {
    /// The monitor example's `--events` file, byte for byte.
    pub events: String,
    /// The monitor example's `--thresholds` file (with `planner`).
    pub thresholds: Option<String>,
    /// Counts, states, the trace's skipped rows: a JSON object.
    pub summary: String,
    /// The timeline's bins for the plot (when asked).
    pub plot: Option<plot::Bins>,
}

/// The page's side of the second pass: the events file and the plot, and the
/// progress every `PROGRESS_EVERY` samples.
struct PageSink<'a> {
    events: EventsWriter<Vec<u8>>,
    plot: Option<plot::Bins>,
    done: u64,
    total: u64,
    progress: &'a mut dyn FnMut(u8, f64),
}

/// Samples between two progress reports.
const PROGRESS_EVERY: u64 = 1 << 16;

impl replay::Sink for PageSink<'_> {
    fn event(&mut self, e: &misalign::monitor::Event) -> Result<(), Box<dyn std::error::Error>> {
        Ok(self.events.event(e)?)
    }

    fn sample(
        &mut self,
        replay: &Replay,
        state: RiskState,
    ) -> Result<(), Box<dyn std::error::Error>> {
        if let Some(plot) = &mut self.plot {
            plot.add(replay.elapsed_ms(), state, replay.reading());
        }
        self.done += 1;
        if self.done.is_multiple_of(PROGRESS_EVERY) {
            (self.progress)(2, self.done as f64 / self.total.max(1) as f64);
        }
        Ok(())
    }
}

/// A reader that counts the bytes it gave (the first pass's progress).
struct Counted<R> {
    inner: R,
    read: Rc<Cell<u64>>,
}

impl<R: Read> Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.read.set(self.read.get() + n as u64);
        Ok(n)
    }
}

/// The monitor example's replay, as `cargo run --example monitor -- [--trace T]
/// [--scene S] --model M --events E [--plot P --thresholds H]` runs it: a first pass
/// over the samples `open` gives (`None`: the built-in scenario; `size` bytes), then
/// the replay, with the plot's bins if `plot`; `progress(pass, fraction)` now and then.
pub fn review<R: Read>(
    mut open: impl FnMut() -> Option<R>,
    size: u64,
    scene: Option<&str>,
    model: Model,
    (planner, plot): (bool, bool),
    progress: &mut dyn FnMut(u8, f64),
) -> Res<Reviewed> {
    let scene = scene_of(scene)?;
    let read = Rc::new(Cell::new(0u64));
    // 8 MiB a read: each read of the file's slice is a round trip to the browser's
    // file store, and 1 MiB pieces spent twice as long there (140 -> 71 ms for a
    // 33 MB trace's two passes, Chromium).
    let mut reader = || {
        open().map(|inner| {
            BufReader::with_capacity(
                8 << 20,
                Counted {
                    inner,
                    read: read.clone(),
                },
            )
        })
    };
    let first = samples(reader())?;
    let mut n = 0u64;
    let counted = first.inspect(|_| {
        n += 1;
        if n.is_multiple_of(PROGRESS_EVERY) {
            progress(1, read.get() as f64 / size.max(1) as f64);
        }
    });
    let mut survey = Survey::of(counted, planner).map_err(|e| format!("trace: {e}"))?;
    let total = survey.total;
    let mut replay = Replay::new(model, &scene, &mut survey).map_err(|e| e.to_string())?;
    let mut sink = PageSink {
        events: EventsWriter::new(Vec::new()).map_err(|e| e.to_string())?,
        plot: plot.then(plot::Bins::new),
        done: 0,
        total,
        progress,
    };
    let mut second = samples(reader())?;
    replay::run(&mut replay, &mut second, &mut sink).map_err(|e| format!("trace: {e}"))?;
    let thresholds = match replay.thresholds() {
        None => None,
        Some(plan) => Some(output::thresholds_csv(
            &plan.map_err(|e| format!("the planner: {e}"))?.rows,
        )),
    };
    let events = String::from_utf8(sink.events.into_inner()).map_err(|e| e.to_string())?;
    Ok(Reviewed {
        events,
        thresholds,
        summary: summary(&replay, &second, total),
        plot: sink.plot,
    })
}

/// The replay's counts as a JSON object for the page.
fn summary<R: BufRead>(replay: &Replay, samples: &Samples<R>, total: u64) -> String {
    use json::Object;
    let s = replay.statistics();
    let f = s.faults();
    let mut states = Vec::new();
    for state in RiskState::ALL {
        let mut o = Object::new();
        o.str("state", state.as_str());
        o.num("time_s", s.time_in_state_ms(state) as f64 / 1e3);
        o.num("energy_J", s.energy_j(state));
        states.push(o.end());
    }
    let mut faults = Object::new();
    for (name, n) in [
        ("non_finite", f.non_finite),
        ("out_of_range", f.out_of_range),
        ("stuck", f.stuck),
        ("gap", f.gap),
        ("time_backwards", f.time_backwards),
        ("driver", f.driver),
        ("estimator", f.estimator),
        ("sensor", f.sensor),
    ] {
        faults.num(name, f64::from(n));
    }
    let mut o = Object::new();
    o.num("samples", total as f64);
    o.raw("states", &format!("[{}]", states.join(",")));
    o.raw("faults", &faults.end());
    o.num("spikes", s.spikes() as f64);
    o.num("repeated_timestamps", s.repeated_timestamps() as f64);
    o.num("events_dropped", s.events_dropped() as f64);
    o.num("max_slip_ratio", f64::from(s.max_slip_ratio()));
    o.num("max_axial_force_N", f64::from(s.max_axial_force()));
    o.opt("min_margin_rad", s.min_margin().map(f64::from));
    o.opt("friction", replay.friction().map(f64::from));
    o.opt(
        "friction_baseline",
        replay.friction_baseline().map(f64::from),
    );
    o.str("final_state", replay.state().as_str());
    o.opt(
        "time_to_critical_s",
        replay.time_to_critical().map(f64::from),
    );
    if let Some(t) = samples.as_trace() {
        o.str("skipped", &t.skipped().describe());
        o.str("unreadable", &t.unreadable().describe());
    }
    o.end()
}

/// The `--events` file of the monitor example for `trace` (`None`: the built-in
/// scenario) and `scene` (`None`: the demo rollers) on `model`.
pub fn events_text(trace: Option<&[u8]>, scene: Option<&str>, model: Model) -> Res<String> {
    let size = trace.map_or(0, |t| t.len() as u64);
    review(|| trace, size, scene, model, (false, false), &mut |_, _| {}).map(|r| r.events)
}

/// The `--thresholds` file of the monitor example for `trace` and `scene` on `model`.
pub fn thresholds_text(trace: Option<&[u8]>, scene: Option<&str>, model: Model) -> Res<String> {
    let size = trace.map_or(0, |t| t.len() as u64);
    let r = review(|| trace, size, scene, model, (true, false), &mut |_, _| {})?;
    Ok(r.thresholds.unwrap_or_default())
}

/// The planner for a load range the engineer gives: `scene` on `model`, its contact
/// model chosen for loads up to `load_max` (N), under `config`.
pub fn plan_text(scene: Option<&str>, model: Model, load_max: f64, config: &Config) -> Res<String> {
    if !(load_max.is_finite() && load_max > 0.0) {
        return Err(format!("the highest load {load_max} N is not a load"));
    }
    let scene = scene_of(scene)?;
    let range = output::PlanRange::UpTo(load_max as f32);
    let plan = replay::plan(model, &scene, config, load_max, range)
        .map_err(|e| format!("the planner: {e}"))?;
    Ok(output::thresholds_csv(&plan.rows))
}

/// Section 9's contact model for `scene` over loads up to `load_max` (N), as the
/// replay and the node choose it once: `elliptic` or `line`.
pub fn contact_model(scene: Option<&str>, load_max: f64) -> Res<&'static str> {
    let scene = scene_of(scene)?;
    use misalign::reference::ModelChoice;
    match misalign::monitor::model_for_range(&scene, load_max, scenario::ANGLE_MIN) {
        Ok(ModelChoice::Line) => Ok("line"),
        Ok(_) => Ok("elliptic"),
        Err(e) => Err(e.to_string()),
    }
}

fn model_of(name: &str) -> Result<Model, JsError> {
    Model::parse(name).map_err(|e| JsError::new(&e))
}

fn js(e: String) -> JsError {
    JsError::new(&e)
}

/// `events(trace, scene, model)`: the monitor example's `--events` file (`trace`:
/// the trace file's bytes, none for the built-in scenario; `scene`: the scene
/// file's text, none for the demo rollers; `model`: `f32`, `fixed` or `reference`).
#[wasm_bindgen]
pub fn events(
    trace: Option<Vec<u8>>,
    scene: Option<String>,
    model: &str,
) -> Result<String, JsError> {
    events_text(trace.as_deref(), scene.as_deref(), model_of(model)?).map_err(js)
}

/// `thresholds(trace, scene, model)`: the monitor example's `--thresholds` file.
#[wasm_bindgen]
pub fn thresholds(
    trace: Option<Vec<u8>>,
    scene: Option<String>,
    model: &str,
) -> Result<String, JsError> {
    thresholds_text(trace.as_deref(), scene.as_deref(), model_of(model)?).map_err(js)
}

/// The replay of the Review view: `read(offset, length)` gives the trace's bytes (a
/// `Uint8Array`; `size` bytes in all), or `read` is `null` for the built-in scenario;
/// `progress(pass, fraction)` is called now and then (pass 1 the survey, 2 the
/// replay).
#[wasm_bindgen]
pub fn review_trace(
    read: Option<js_sys::Function>,
    size: f64,
    scene: Option<String>,
    model: &str,
    planner: bool,
    progress: js_sys::Function,
) -> Result<Review, JsError> {
    let model = model_of(model)?;
    let mut report = |pass: u8, fraction: f64| {
        let _ = progress.call2(&JsValue::NULL, &pass.into(), &fraction.into());
    };
    let open = || {
        read.as_ref().map(|f| JsSource {
            read: f.clone(),
            size: size as u64,
            offset: 0,
        })
    };
    review(
        open,
        size as u64,
        scene.as_deref(),
        model,
        (planner, true),
        &mut report,
    )
    .map(Review)
    .map_err(js)
}

/// A trace read through a JavaScript function `read(offset, length) -> Uint8Array`
/// (in the worker: `FileReaderSync` over the dropped file's slices).
struct JsSource {
    read: js_sys::Function,
    size: u64,
    offset: u64,
}

impl Read for JsSource {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let want = (self.size.saturating_sub(self.offset)).min(buf.len() as u64);
        if want == 0 {
            return Ok(0);
        }
        let chunk = self
            .read
            .call2(
                &JsValue::NULL,
                &(self.offset as f64).into(),
                &(want as f64).into(),
            )
            .map_err(|e| std::io::Error::other(format!("{e:?}")))?;
        // The function gives a Uint8Array: taken as it is (`Uint8Array::new` would copy).
        let chunk: js_sys::Uint8Array = chunk.unchecked_into();
        let n = (chunk.length() as usize).min(buf.len());
        chunk.subarray(0, n as u32).copy_to(&mut buf[..n]);
        self.offset += n as u64;
        Ok(n)
    }
}

/// A replay's outcome for the page.
#[wasm_bindgen]
pub struct Review(Reviewed);

#[wasm_bindgen]
impl Review {
    /// The `--events` file.
    #[wasm_bindgen(getter)]
    pub fn events(&self) -> String {
        self.0.events.clone()
    }
    /// The `--thresholds` file (empty unless asked).
    #[wasm_bindgen(getter)]
    pub fn thresholds(&self) -> String {
        self.0.thresholds.clone().unwrap_or_default()
    }
    /// The summary (JSON).
    #[wasm_bindgen(getter)]
    pub fn summary(&self) -> String {
        self.0.summary.clone()
    }
    /// The width of a plot bin (s).
    #[wasm_bindgen(getter)]
    pub fn bin_s(&self) -> f64 {
        self.plot().bin_s()
    }
    /// How many bins.
    #[wasm_bindgen(getter)]
    pub fn bins(&self) -> usize {
        self.plot().len()
    }
    /// Curve `k`'s lowest value in each bin (NaN: none there).
    pub fn low(&self, k: usize) -> Vec<f32> {
        self.plot().low(k)
    }
    /// Curve `k`'s highest value in each bin.
    pub fn high(&self, k: usize) -> Vec<f32> {
        self.plot().high(k)
    }
    /// Each bin's most severe state (`RiskState::index`; 255 none).
    pub fn states(&self) -> Vec<u8> {
        self.plot().states()
    }
}

impl Review {
    fn plot(&self) -> &plot::Bins {
        static EMPTY: plot::Bins = plot::Bins::new();
        self.0.plot.as_ref().unwrap_or(&EMPTY)
    }
}

/// `plan(scene, model, loadMax)`: the planner's table for the engineer's load range
/// under the default configuration (`PageNode.thresholds` under a committed one).
#[wasm_bindgen]
pub fn plan(scene: Option<String>, model: &str, load_max: f64) -> Result<String, JsError> {
    let model = model_of(model)?;
    plan_text(scene.as_deref(), model, load_max, &Config::default()).map_err(js)
}

/// `contactModel(scene, loadMax)`: `elliptic` or `line`, section 9's choice.
#[wasm_bindgen(js_name = contactModel)]
pub fn contact_model_js(scene: Option<String>, load_max: f64) -> Result<String, JsError> {
    contact_model(scene.as_deref(), load_max)
        .map(str::to_string)
        .map_err(js)
}

/// `estimate(csv, args)`: the CSV estimator (`cargo run --example estimate -- ARGS <
/// CSV`): `{code, out, err}`. With `--solve mu` or `--solve phi` its inverses.
#[wasm_bindgen]
pub fn estimate(input: &str, args: Vec<String>) -> Estimated {
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = misalign_cli::estimate::run(&args, input.as_bytes(), &mut out, &mut err);
    Estimated {
        code,
        out: String::from_utf8_lossy(&out).into_owned(),
        err: String::from_utf8_lossy(&err).into_owned(),
    }
}

/// The CSV estimator's exit code, output and messages.
#[wasm_bindgen(getter_with_clone)]
pub struct Estimated {
    /// 0, 1 or 2 as the example's exit status.
    pub code: i32,
    /// stdout: the result rows.
    pub out: String,
    /// stderr: the messages.
    pub err: String,
}

/// `prepareScene(scene, fpu)`: the scene file's scene prepared for a node's core as
/// tools/commission.py prepares it (`float::Auto` with an FPU, else `fixed::FixedAuto`).
#[wasm_bindgen(js_name = prepareScene)]
pub fn prepare_scene(scene: &str, fpu: bool) -> Result<Vec<u8>, JsError> {
    let scene = scene_of(Some(scene)).map_err(js)?;
    misalign_cli::prepare::prepared(&scene, &misalign_cli::prepare::Options::for_core(fpu))
        .map_err(|e| JsError::new(&format!("scene: {e}")))
}

/// `defaultCode()`: the site code a node has until a commit changes it
/// (`misalign::modbus::DEFAULT_UNLOCK_CODE`).
#[wasm_bindgen(js_name = defaultCode)]
pub fn default_code() -> u16 {
    misalign::modbus::DEFAULT_UNLOCK_CODE
}

/// `f32Text(bits)`: an f32 as Rust prints it (the shortest digits that read back),
/// as the PC tools write their files.
#[wasm_bindgen(js_name = f32Text)]
pub fn f32_text(bits: u32) -> String {
    f32::from_bits(bits).to_string()
}
