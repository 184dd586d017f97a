//! `misalign._misalign`: the compiled half of the Python package. It takes checked,
//! contiguous f64 columns from `misalign/__init__.py` (which broadcasts, converts
//! dtypes and raises `ValueError` for bad shapes and options) and answers with numpy
//! arrays; every long call releases the GIL.

use misalign::batch::{self, Column, Counts, Details, Inputs, Model, Outputs, RefusedLsb};
use misalign::fixed::{FixedAuto, FixedEllipticScene};
use misalign::float::Auto;
use misalign::monitor::{
    Config, Event, FaultCounts, Monitor, Reading, RiskState, Sample, Thresholds, model_for_range,
    scenario,
};
use misalign::reference::ModelChoice;
use misalign::reference::inverse::{self, Inverse};
use misalign::{Error, Estimator, Scene};
use misalign_cli::monitor_input::TraceClock;
use misalign_cli::monitor_output as output;
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn choice_of(contact: &str) -> PyResult<ModelChoice> {
    match contact {
        "auto" => Ok(ModelChoice::Section9),
        "elliptic" => Ok(ModelChoice::Elliptic),
        "line" => Ok(ModelChoice::Line),
        _ => Err(value_error(format!(
            "contact must be 'auto', 'elliptic' or 'line', not {contact:?}"
        ))),
    }
}

/// A column of one value (a scalar that broadcasts) or of `n`.
fn column<'a>(x: &'a [f64], n: usize, name: &str) -> PyResult<Column<'a>> {
    match x.len() {
        1 => Ok(Column::One(x[0])),
        m if m == n => Ok(Column::Each(x)),
        m => Err(value_error(format!("{name} has {m} rows, not 1 or {n}"))),
    }
}

/// A numpy array of `n` elements as `numpy.empty` makes it: numpy's allocator (which
/// asks the kernel for huge pages on large arrays: fewer page faults while the rows
/// are written than a fresh Vec's), and no zeroing of memory that the batch then writes
/// over in full (every output column gets every row).
fn empty<'py, T: numpy::Element>(py: Python<'py>, n: usize) -> PyResult<Bound<'py, PyArray1<T>>> {
    let array = py
        .import("numpy")?
        .getattr("empty")?
        .call1((n, numpy::dtype::<T>(py)))?;
    Ok(array.cast_into::<PyArray1<T>>()?)
}

/// [`batch::estimate`] on this thread, through its AVX2 build where the CPU has AVX2
/// (the same numbers bit for bit; the reference's SIMD lanes twice as wide).
fn rows_here(
    inputs: &Inputs<'_>,
    out: &mut Outputs<'_>,
    model: Model,
) -> Result<usize, batch::Mismatch> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: `estimate_avx2` is compiled for AVX2 alone, which this CPU has.
        return unsafe { batch::estimate_avx2(inputs, out, model) };
    }
    batch::estimate(inputs, out, model)
}

/// The ADC's load LSB where none is given (N): 10 mN, as the nodes.
const ADC_LOAD_LSB: f64 = 1e-2;

/// A ValueError naming an ADC's LSB that the fixed-point core cannot take for the
/// scene of a row it refused (out of range), rather than blaming that row.
fn refused_lsb(
    inputs: &Inputs<'_>,
    status: &[u8],
    load_lsb: f64,
    angle_lsb: Option<f64>,
) -> PyResult<()> {
    let out_of_range = batch::status_of(Error::OutOfRange);
    let at = |c: Column<'_>, i: usize| match c {
        Column::One(x) => x,
        Column::Each(x) => x[i],
    };
    let mut checked: Option<[u64; 6]> = None;
    for (i, _) in status.iter().enumerate().filter(|(_, s)| **s == out_of_range) {
        let constants = [
            at(inputs.r1, i),
            at(inputs.r2, i),
            at(inputs.shear_modulus, i),
            at(inputs.poisson_ratio, i),
            at(inputs.friction, i),
            inputs.length.map_or(f64::NAN, |l| at(l, i)),
        ];
        let key = constants.map(f64::to_bits);
        if checked == Some(key) {
            continue;
        }
        checked = Some(key);
        let [r1, r2, g, nu, mu, length] = constants;
        let Ok(scene) = Scene::new(r1, r2, g, nu, mu)
            .and_then(|s| if length.is_nan() { Ok(s) } else { s.with_length(length) })
        else {
            continue;
        };
        let finest = FixedEllipticScene::min_angle_lsb(&scene).max(1e-10);
        let angle = angle_lsb.map_or("the finest angle its tables allow".to_string(), |a| {
            format!("angle_lsb = {a:e} rad")
        });
        let which = match batch::adc_lsb_refused(&scene, inputs.choice, load_lsb, angle_lsb) {
            None => continue,
            Some(RefusedLsb::Load) => format!(
                "load_lsb = {load_lsb:e} N: the fixed-point core cannot take it"
            ),
            Some(RefusedLsb::Angle) => format!(
                "{angle}: the fixed-point core cannot take it (one count must be at least \
                 {finest:e} rad, theta = c |phi| >= 2^-40 rad on its tables, and at most pi/2)"
            ),
            Some(RefusedLsb::Both) => format!(
                "load_lsb = {load_lsb:e} N with {angle}: the fixed-point core cannot take the two together"
            ),
        };
        let scene_of = if inputs.one_scene_for_all() {
            "the scene".to_string()
        } else {
            format!("the scene of row {i}")
        };
        return Err(value_error(format!(
            "{which} for {scene_of} (constants outside its Q8.24 logarithms, or d/b and F \
             beyond 2^+-126 over its range)"
        )));
    }
    Ok(())
}

const NAMES: [&str; 8] = ["R1", "R2", "G", "nu", "mu", "length", "P", "phi"];

/// The messages of the status codes: index = status (0 = fine: "").
#[pyfunction]
fn error_messages() -> Vec<String> {
    (0..=u8::MAX)
        .map_while(|code| match code {
            0 => Some(String::new()),
            c => batch::error_of(c).map(|e| e.to_string()),
        })
        .collect()
}

/// The forward model over columns `R1, R2, G, nu, mu, length, P, phi` (each 1 or n
/// rows; length ignored unless `has_length`).
#[pyfunction]
#[pyo3(signature = (columns, has_length, n, model, contact, details, counts, load_lsb, angle_lsb, threads))]
#[allow(clippy::too_many_arguments)]
fn estimate<'py>(
    py: Python<'py>,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    has_length: bool,
    n: usize,
    model: &str,
    contact: &str,
    details: bool,
    counts: &str,
    load_lsb: Option<f64>,
    angle_lsb: Option<f64>,
    threads: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let model = match (model, counts) {
        ("reference", _) => Model::Reference,
        ("f32", _) => Model::F32,
        ("fixed", "exact") => Model::Fixed(Counts::Exact),
        ("fixed", "adc") => Model::Fixed(Counts::Adc {
            load_lsb: load_lsb.unwrap_or(ADC_LOAD_LSB),
            angle_lsb,
        }),
        ("fixed", _) => {
            return Err(value_error(format!(
                "counts must be 'exact' or 'adc', not {counts:?}"
            )));
        }
        _ => {
            return Err(value_error(format!(
                "model must be 'reference', 'f32' or 'fixed', not {model:?}"
            )));
        }
    };
    let choice = choice_of(contact)?;
    if columns.len() != 8 {
        return Err(value_error("eight columns expected"));
    }
    let slices = columns
        .iter()
        .map(|c| c.as_slice().map_err(value_error))
        .collect::<PyResult<Vec<&[f64]>>>()?;
    let mut cols = Vec::with_capacity(8);
    for (s, name) in slices.iter().zip(NAMES) {
        cols.push(column(s, n, name)?);
    }
    let inputs = Inputs {
        r1: cols[0],
        r2: cols[1],
        shear_modulus: cols[2],
        poisson_ratio: cols[3],
        friction: cols[4],
        length: has_length.then_some(cols[5]),
        load: cols[6],
        phi: cols[7],
        choice,
    };
    let floats = (0..if details { 15 } else { 3 })
        .map(|_| empty::<f64>(py, n))
        .collect::<PyResult<Vec<_>>>()?;
    let codes = (0..4)
        .map(|_| empty::<u8>(py, n))
        .collect::<PyResult<Vec<_>>>()?;
    let mut float_guards: Vec<_> = floats.iter().map(|a| a.readwrite()).collect();
    let mut code_guards: Vec<_> = codes.iter().map(|a| a.readwrite()).collect();
    let mut float_slices = float_guards
        .iter_mut()
        .map(|g| g.as_slice_mut().map_err(value_error))
        .collect::<PyResult<Vec<&mut [f64]>>>()?;
    let mut code_slices = code_guards
        .iter_mut()
        .map(|g| g.as_slice_mut().map_err(value_error))
        .collect::<PyResult<Vec<&mut [u8]>>>()?;
    py.detach(|| {
        let [regime, model_code, flags, status] = code_slices.as_mut_slice() else {
            return Ok(0); // not reached: four code columns were made above
        };
        let (main, extra) = float_slices.split_at_mut(3);
        let [s, f, phi0] = main else {
            return Ok(0); // not reached: three number columns were made above
        };
        let details = match extra {
            [
                theta,
                kprime,
                m,
                nn,
                a,
                b,
                p0,
                d,
                pstar,
                p0star,
                theta0,
                radius,
            ] => Some(Details {
                theta,
                kprime,
                m,
                n: nn,
                a,
                b,
                p0,
                d,
                pstar,
                p0star,
                theta0,
                radius,
            }),
            _ => None,
        };
        let mut out = Outputs {
            slip_ratio: s,
            axial_force: f,
            critical_angle: phi0,
            regime,
            model: model_code,
            flags,
            status,
            details,
        };
        if threads {
            batch::par_estimate_with(&inputs, &mut out, model, &rows_here)
        } else {
            rows_here(&inputs, &mut out, model)
        }
    })
    .map_err(value_error)?;
    if let Model::Fixed(Counts::Adc {
        load_lsb,
        angle_lsb,
    }) = model
    {
        refused_lsb(&inputs, code_slices[3], load_lsb, angle_lsb)?;
    }
    drop(float_slices);
    drop(code_slices);
    drop(float_guards);
    drop(code_guards);
    let dict = PyDict::new(py);
    let names = [
        "s", "F", "phi0", "theta", "kprime", "m", "n", "a", "b", "p0", "d", "Pstar", "P0star",
        "theta0", "R",
    ];
    for (name, col) in names.into_iter().zip(floats) {
        dict.set_item(name, col)?;
    }
    for (name, col) in ["regime_code", "model_code", "flags", "status"]
        .into_iter()
        .zip(codes)
    {
        dict.set_item(name, col)?;
    }
    Ok(dict)
}

/// Messages deduplicated into codes (0 = fine).
#[derive(Default)]
struct Messages(Vec<String>);

impl Messages {
    fn code(&mut self, message: String) -> u16 {
        let at = match self.0.iter().position(|m| *m == message) {
            Some(i) => i,
            None => {
                self.0.push(message);
                self.0.len() - 1
            }
        };
        u16::try_from(at + 1).unwrap_or(u16::MAX)
    }
}

/// f32's range for an input of the f32 inverse (NaN and infinities pass to the core's
/// typed errors).
fn narrow(name: &str, x: f64) -> Result<f32, String> {
    let y = x as f32;
    if x.is_finite() && (y.is_infinite() || (y == 0.0 && x != 0.0)) {
        return Err(format!("f32 core: {name} = {x:e} is outside f32's range"));
    }
    Ok(y)
}

/// One row of an inverse: mu from (P, phi, F) or phi from (P, F).
fn solve_row(
    unknown_mu: bool,
    f32_core: bool,
    choice: ModelChoice,
    scene: &Scene,
    load: f64,
    phi: f64,
    force: f64,
) -> Result<Inverse<f64>, String> {
    let text = |e: Error| e.to_string();
    if f32_core {
        let core = Auto::with_choice(scene, choice).map_err(text)?;
        let (p, f) = (narrow("P", load)?, narrow("F", force)?);
        let answer = if unknown_mu && phi.abs() > core::f64::consts::FRAC_PI_2 {
            // Refused before f32's rounding carries it onto f32's FRAC_PI_2, as in the
            // reference.
            Err(Error::Angle)
        } else if unknown_mu {
            core.friction_from_axial_force(p, narrow("phi", phi)?, f)
        } else {
            core.angle_from_axial_force(p, f)
        };
        return Ok(answer.map_err(text)?.map(f64::from));
    }
    let per_length = |v: f64| v / scene.length().unwrap_or(1.0);
    let answer = match (unknown_mu, choice) {
        (true, ModelChoice::Section9) => inverse::friction_estimate(scene, load, phi, force),
        (true, ModelChoice::Elliptic) => inverse::friction_elliptic(scene, load, phi, force),
        (true, ModelChoice::Line) => {
            inverse::friction_line(scene, per_length(load), phi, per_length(force))
        }
        (false, ModelChoice::Section9) => inverse::angle_estimate(scene, load, force),
        (false, ModelChoice::Elliptic) => inverse::angle_elliptic(scene, load, force),
        (false, ModelChoice::Line) => {
            inverse::angle_line(scene, per_length(load), per_length(force))
        }
    };
    answer.map_err(text)
}

/// The friction of the mu-inverse's scenes: `Scene::new` needs one; the inverse does
/// not read it.
const PLACEHOLDER_FRICTION: f64 = 1.0;

/// The inverses over columns `R1, R2, G, nu, mu, length, P, phi, F`: `unknown` "mu"
/// (mu column ignored) or "phi" (phi column ignored). Returns value, bound code (0
/// exact, 1 at least, 2 inconsistent, 255 error), sensitivity, message code and the
/// messages.
#[pyfunction]
#[pyo3(signature = (unknown, columns, has_length, n, model, contact))]
fn solve<'py>(
    py: Python<'py>,
    unknown: &str,
    columns: Vec<PyReadonlyArray1<'py, f64>>,
    has_length: bool,
    n: usize,
    model: &str,
    contact: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let unknown_mu = match unknown {
        "mu" => true,
        "phi" => false,
        _ => return Err(value_error("unknown must be 'mu' or 'phi'")),
    };
    let f32_core = match model {
        "reference" => false,
        "f32" => true,
        "fixed" => {
            return Err(value_error(
                "the fixed-point core has no inverse: use model='reference' or 'f32'",
            ));
        }
        _ => return Err(value_error("model must be 'reference' or 'f32'")),
    };
    let choice = choice_of(contact)?;
    if columns.len() != 9 {
        return Err(value_error("nine columns expected"));
    }
    let slices = columns
        .iter()
        .map(|c| c.as_slice().map_err(value_error))
        .collect::<PyResult<Vec<&[f64]>>>()?;
    let names = ["R1", "R2", "G", "nu", "mu", "length", "P", "phi", "F"];
    let mut cols = Vec::with_capacity(9);
    for (s, name) in slices.iter().zip(names) {
        cols.push(column(s, n, name)?);
    }
    let at = |c: &Column<'_>, i: usize| match c {
        Column::One(x) => *x,
        Column::Each(x) => x[i],
    };
    let mut value = vec![f64::NAN; n];
    let mut bound = vec![u8::MAX; n];
    let mut sensitivity = vec![f64::NAN; n];
    let mut code = vec![0u16; n];
    let mut messages = Messages::default();
    py.detach(|| {
        for i in 0..n {
            let mu = if unknown_mu {
                PLACEHOLDER_FRICTION
            } else {
                at(&cols[4], i)
            };
            let scene = Scene::new(
                at(&cols[0], i),
                at(&cols[1], i),
                at(&cols[2], i),
                at(&cols[3], i),
                mu,
            )
            .and_then(|s| {
                if has_length {
                    s.with_length(at(&cols[5], i))
                } else {
                    Ok(s)
                }
            })
            .map_err(|e| e.to_string());
            let phi = if unknown_mu { at(&cols[7], i) } else { 0.0 };
            let answer = scene.and_then(|s| {
                solve_row(
                    unknown_mu,
                    f32_core,
                    choice,
                    &s,
                    at(&cols[6], i),
                    phi,
                    at(&cols[8], i),
                )
            });
            match answer {
                Ok(a) => {
                    value[i] = a.value().unwrap_or(f64::NAN);
                    sensitivity[i] = a.sensitivity().unwrap_or(f64::NAN);
                    bound[i] = match a {
                        Inverse::Exact { .. } => 0,
                        Inverse::AtLeast { .. } => 1,
                        Inverse::Inconsistent(why) => {
                            code[i] = messages.code(why.as_str().to_string());
                            2
                        }
                    };
                }
                Err(e) => code[i] = messages.code(e),
            }
        }
    });
    let dict = PyDict::new(py);
    dict.set_item("value", value.into_pyarray(py))?;
    dict.set_item("bound_code", bound.into_pyarray(py))?;
    dict.set_item("sensitivity", sensitivity.into_pyarray(py))?;
    dict.set_item("code", code.into_pyarray(py))?;
    let mut all = vec![String::new()];
    all.extend(messages.0);
    dict.set_item("messages", all)?;
    Ok(dict)
}

/// The built-in scenario's samples: time (ms, the node's wrapping counter), P (N),
/// phi (rad), V (m/s; NaN where not measured), F (N; NaN where not measured).
#[pyfunction]
fn scenario_samples<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
    let samples: Vec<Sample> = scenario::Scenario::new().collect();
    let dict = PyDict::new(py);
    let col = |f: fn(&Sample) -> f32| samples.iter().map(f).collect::<Vec<f32>>();
    let time: Vec<u32> = samples.iter().map(|s| s.time_ms).collect();
    dict.set_item("time_ms", time.into_pyarray(py))?;
    dict.set_item("P", col(|s| s.load).into_pyarray(py))?;
    dict.set_item("phi", col(|s| s.phi).into_pyarray(py))?;
    dict.set_item("V", col(|s| s.speed.unwrap_or(f32::NAN)).into_pyarray(py))?;
    dict.set_item(
        "F",
        col(|s| s.axial_force.unwrap_or(f32::NAN)).into_pyarray(py),
    )?;
    let [r1, r2, g, nu, mu] = scenario::SCENE;
    dict.set_item("scene", (r1, r2, g, nu, mu))?;
    dict.set_item("load_max", scenario::LOAD_MAX)?;
    dict.set_item("angle_min", scenario::ANGLE_MIN)?;
    Ok(dict)
}

/// A Python bool (or numpy's), which numbers' conversions would take as 0 or 1.
fn is_bool(value: &Bound<'_, PyAny>) -> bool {
    value.is_instance_of::<pyo3::types::PyBool>()
        || value
            .get_type()
            .fully_qualified_name()
            .is_ok_and(|n| n.to_string() == "numpy.bool" || n.to_string() == "numpy.bool_")
}

/// A configuration field of f32: a real number (not a bool) that f32 holds finite.
fn number_field(key: &str, value: &Bound<'_, PyAny>) -> PyResult<f32> {
    let x = if is_bool(value) {
        None
    } else {
        value.extract::<f64>().ok()
    };
    match x {
        Some(x) if x.is_finite() && (x as f32).is_finite() => Ok(x as f32),
        _ => Err(value_error(format!(
            "config: {key} must be a finite number within f32's range (+-3.4e38), not {}",
            value.repr()?
        ))),
    }
}

/// A configuration field in ms: a whole number (not a bool) from 0 to 2^32 - 1.
fn ms_field(key: &str, value: &Bound<'_, PyAny>) -> PyResult<u32> {
    let x = if is_bool(value) {
        None
    } else {
        value.extract::<u32>().ok()
    };
    x.ok_or_else(|| {
        value_error(format!(
            "config: {key} must be a whole number of ms from 0 to 4294967295, not {}",
            value.repr().map_or_else(|_| "that".to_string(), |r| r.to_string())
        ))
    })
}

/// A configuration switch: True or False (Python's or numpy's).
fn flag_field(key: &str, value: &Bound<'_, PyAny>) -> PyResult<bool> {
    if is_bool(value) {
        value.is_truthy()
    } else {
        Err(value_error(format!(
            "config: {key} must be True or False, not {}",
            value.repr()?
        )))
    }
}

/// The monitor's configuration: the default with the given fields replaced.
fn config_of(overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Config> {
    let mut c = Config::default();
    let Some(d) = overrides else {
        return Ok(c);
    };
    let (mut warning, mut alarm, mut deadband, mut on_margin) = match c.thresholds {
        Thresholds::SlipRatio {
            warning,
            alarm,
            deadband,
        } => (warning, alarm, deadband, false),
        Thresholds::Margin {
            warning,
            alarm,
            deadband,
        } => (warning, alarm, deadband, true),
    };
    for (key, value) in d.iter() {
        let Ok(key) = key.extract::<String>() else {
            return Err(value_error(format!(
                "config: a field's name is a str, not {}",
                key.repr()?
            )));
        };
        let f = || number_field(&key, &value);
        let ms = || ms_field(&key, &value);
        let on = || flag_field(&key, &value);
        match key.as_str() {
            "thresholds" => {
                on_margin = match value.extract::<String>().as_deref() {
                    Ok("slip_ratio") => false,
                    Ok("margin") => true,
                    _ => {
                        return Err(value_error(format!(
                            "config: thresholds must be 'slip_ratio' or 'margin', not {}",
                            value.repr()?
                        )));
                    }
                };
            }
            "warning" => warning = f()?,
            "alarm" => alarm = f()?,
            "deadband" => deadband = f()?,
            "on_delay_ms" => c.on_delay_ms = ms()?,
            "off_delay_ms" => c.off_delay_ms = ms()?,
            "fault_delay_ms" => c.fault_delay_ms = ms()?,
            "inhibit_ms" => c.inhibit_ms = ms()?,
            "stuck_ms" => c.stuck_ms = ms()?,
            "gap_ms" => c.gap_ms = ms()?,
            "stop_load" => c.stop_load = f()?,
            "stop_speed" => c.stop_speed = f()?,
            "nominal_speed" => c.nominal_speed = f()?,
            "load_min" => c.load_min = f()?,
            "load_max" => c.load_max = f()?,
            "angle_max" => c.angle_max = f()?,
            "speed_max" => c.speed_max = f()?,
            "force_max" => c.force_max = f()?,
            "smoothing_tau_s" => c.smoothing_tau_s = f()?,
            "spikes" => {
                if !on()? {
                    c.spikes = None;
                }
            }
            "trend" => {
                if !on()? {
                    c.trend = None;
                }
            }
            "friction" => {
                if !on()? {
                    c.friction = None;
                }
            }
            other => return Err(value_error(format!("unknown config field {other:?}"))),
        }
    }
    c.thresholds = if on_margin {
        Thresholds::Margin {
            warning,
            alarm,
            deadband,
        }
    } else {
        Thresholds::SlipRatio {
            warning,
            alarm,
            deadband,
        }
    };
    c.validate()
        .map_err(|e| value_error(format!("config: {e}")))?;
    Ok(c)
}

/// The scene of the replay and the planner.
fn scene_of(scene: (f64, f64, f64, f64, f64), length: Option<f64>) -> PyResult<Scene> {
    let (r1, r2, g, nu, mu) = scene;
    let s = Scene::new(r1, r2, g, nu, mu).map_err(|e| value_error(format!("scene: {e}")))?;
    match length {
        Some(l) => s
            .with_length(l)
            .map_err(|e| value_error(format!("scene: {e}"))),
        None => Ok(s),
    }
}

/// The monitor example's cores: the f32 core, or the fixed-point core at 10 mN per
/// count and the finest angle its tables allow (at least 0.1 nrad); one model for
/// the trace's operating range (up to `load_max`).
enum Core {
    F32(Box<Monitor<Auto>>),
    Fixed(Box<Monitor<FixedAuto>>),
}

fn choice_for(scene: &Scene, load_max: f64) -> PyResult<ModelChoice> {
    model_for_range(scene, load_max, scenario::ANGLE_MIN).map_err(value_error)
}

fn fixed_core(scene: &Scene, choice: ModelChoice) -> Result<FixedAuto, Error> {
    let angle_lsb = match choice {
        ModelChoice::Elliptic => FixedEllipticScene::min_angle_lsb(scene).max(1e-10),
        _ => 1e-10,
    };
    FixedAuto::with_choice(scene, 1e-2, angle_lsb, choice)
}

/// Columns of the events, as the monitor example's `--events` CSV.
#[derive(Default)]
struct EventColumns {
    t: Vec<f64>,
    seq: Vec<u32>,
    state: Vec<String>,
    from: Vec<String>,
    kind: Vec<&'static str>,
    fault: Vec<String>,
    load: Vec<f64>,
    phi: Vec<f64>,
    s: Vec<f64>,
    force: Vec<f64>,
    phi0: Vec<f64>,
    margin: Vec<f64>,
    time_to_critical: Vec<f64>,
    time_ms: Vec<u32>,
}

impl EventColumns {
    /// The event's cells of the monitor example's `--events` row, NaN for an empty
    /// number.
    fn push(&mut self, e: &Event) {
        let rec = output::event_record(e);
        let num =
            |f: fn(&Reading) -> f32| rec.reading.as_ref().map_or(f64::NAN, |r| f64::from(f(r)));
        let opt = |f: fn(&Reading) -> Option<f32>| {
            rec.reading.as_ref().and_then(f).map_or(f64::NAN, f64::from)
        };
        self.t.push(rec.t);
        self.seq.push(rec.seq);
        self.load.push(num(|r| r.load));
        self.phi.push(num(|r| r.phi));
        self.s.push(num(|r| r.slip_ratio));
        self.force.push(num(|r| r.axial_force));
        self.phi0.push(opt(|r| r.critical_angle));
        self.margin.push(opt(|r| r.margin));
        self.time_to_critical
            .push(rec.time_to_critical_s.map_or(f64::NAN, f64::from));
        self.time_ms.push(rec.time_ms);
        self.state.push(rec.state);
        self.from.push(rec.from.to_string());
        self.kind.push(rec.kind);
        self.fault.push(rec.fault);
    }
}

/// The condition monitor over a recorded trace, fed in chunks (the Python side draws
/// a progress bar between them).
#[pyclass(module = "misalign._misalign")]
struct Replay {
    core: Core,
    events: EventColumns,
    /// The trace's times as the node's counter, checked as the monitor example checks
    /// them (across calls of `feed`).
    clock: TraceClock,
    /// Samples fed so far: the index a message names.
    fed: u64,
}

fn drain<E: Estimator>(m: &mut Monitor<E>, events: &mut EventColumns) {
    while let Some(e) = m.pop_event() {
        events.push(&e);
    }
}

fn feed_monitor<E: Estimator>(
    m: &mut Monitor<E>,
    step: fn(&mut Monitor<E>, Sample) -> RiskState,
    events: &mut EventColumns,
    samples: impl Iterator<Item = Sample>,
) {
    for s in samples {
        step(m, s);
        drain(m, events);
    }
}

#[pymethods]
impl Replay {
    #[new]
    #[pyo3(signature = (scene, length, model, load_max, config=None))]
    fn new(
        scene: (f64, f64, f64, f64, f64),
        length: Option<f64>,
        model: &str,
        load_max: f64,
        config: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let scene = scene_of(scene, length)?;
        let config = config_of(config)?;
        let choice = choice_for(&scene, load_max)?;
        let monitor_error =
            |e: misalign::monitor::ConfigError| value_error(format!("configuration: {e}"));
        let core = match model {
            "f32" => Core::F32(Box::new(
                Monitor::new(
                    Auto::with_choice(&scene, choice).map_err(value_error)?,
                    config,
                )
                .map_err(monitor_error)?,
            )),
            "fixed" => Core::Fixed(Box::new(
                Monitor::new(fixed_core(&scene, choice).map_err(value_error)?, config)
                    .map_err(monitor_error)?,
            )),
            _ => {
                return Err(value_error(format!(
                    "model must be 'f32' or 'fixed', not {model:?}"
                )));
            }
        };
        Ok(Replay {
            core,
            events: EventColumns::default(),
            clock: TraceClock::new(),
            fed: 0,
        })
    }

    /// Feeds samples: time (s, finite), P (N), phi (rad), V (m/s), F (N); NaN in V or
    /// F is "not measured" for that sample. Each becomes what the monitor example's
    /// trace reader makes of it: t the node's wrapping u32 ms counter (rounded half
    /// away from zero), the others f32. Raises ValueError, naming the sample, for a t
    /// that counter cannot hold: beyond 2^53 ms, or a step of 2^31 ms or more outside
    /// the counter's own range (0 to 2^32 ms).
    fn feed(
        &mut self,
        py: Python<'_>,
        time_s: PyReadonlyArray1<'_, f64>,
        load: PyReadonlyArray1<'_, f64>,
        phi: PyReadonlyArray1<'_, f64>,
        speed: PyReadonlyArray1<'_, f64>,
        force: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<()> {
        let t = time_s.as_slice().map_err(value_error)?;
        let p = load.as_slice().map_err(value_error)?;
        let a = phi.as_slice().map_err(value_error)?;
        let v = speed.as_slice().map_err(value_error)?;
        let f = force.as_slice().map_err(value_error)?;
        let n = t.len();
        if [p.len(), a.len(), v.len(), f.len()].iter().any(|&m| m != n) {
            return Err(value_error("trace columns of different lengths"));
        }
        if let Some(i) = t.iter().position(|x| !x.is_finite()) {
            return Err(value_error(format!(
                "t is not a finite number at sample {i}"
            )));
        }
        // A time the node's counter cannot hold (t in ns, a step of 24.8 days or more)
        // refuses the trace, as in the monitor example; nothing of this call is fed.
        let mut clock = self.clock;
        let time_ms = t
            .iter()
            .enumerate()
            .map(|(i, &x)| {
                clock
                    .time_ms(x)
                    .map_err(|m| value_error(format!("sample {}: {m}", self.fed + i as u64)))
            })
            .collect::<PyResult<Vec<u32>>>()?;
        (self.clock, self.fed) = (clock, self.fed + n as u64);
        let Replay { core, events, .. } = self;
        py.detach(|| {
            let samples = (0..n).map(|i| {
                let mut s = Sample::new(time_ms[i], p[i] as f32, a[i] as f32);
                s.speed = (!v[i].is_nan()).then_some(v[i] as f32);
                s.axial_force = (!f[i].is_nan()).then_some(f[i] as f32);
                s
            });
            match core {
                Core::F32(m) => feed_monitor(m, Monitor::process_with_friction, events, samples),
                Core::Fixed(m) => feed_monitor(m, Monitor::process, events, samples),
            }
        });
        Ok(())
    }

    /// The events so far, as columns.
    fn events<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let e = &self.events;
        let d = PyDict::new(py);
        d.set_item("t", e.t.clone().into_pyarray(py))?;
        d.set_item("seq", e.seq.clone().into_pyarray(py))?;
        d.set_item("state", e.state.clone())?;
        d.set_item("from", e.from.clone())?;
        d.set_item("kind", e.kind.clone())?;
        d.set_item("fault", e.fault.clone())?;
        d.set_item("P", e.load.clone().into_pyarray(py))?;
        d.set_item("phi", e.phi.clone().into_pyarray(py))?;
        d.set_item("s", e.s.clone().into_pyarray(py))?;
        d.set_item("F", e.force.clone().into_pyarray(py))?;
        d.set_item("phi0", e.phi0.clone().into_pyarray(py))?;
        d.set_item("margin", e.margin.clone().into_pyarray(py))?;
        d.set_item(
            "time_to_critical",
            e.time_to_critical.clone().into_pyarray(py),
        )?;
        d.set_item("time_ms", e.time_ms.clone().into_pyarray(py))?;
        Ok(d)
    }

    /// The monitor's statistics and final state.
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        match &self.core {
            Core::F32(m) => summary(py, m),
            Core::Fixed(m) => summary(py, m),
        }
    }
}

fn summary<'py, E: Estimator>(py: Python<'py>, m: &Monitor<E>) -> PyResult<Bound<'py, PyDict>> {
    let s = m.statistics();
    let d = PyDict::new(py);
    let states: Vec<&str> = RiskState::ALL.iter().map(|r| r.as_str()).collect();
    let time_s: Vec<f64> = RiskState::ALL
        .iter()
        .map(|&r| s.time_in_state_ms(r) as f64 / 1e3)
        .collect();
    let energy: Vec<f64> = RiskState::ALL.iter().map(|&r| s.energy_j(r)).collect();
    d.set_item("states", states)?;
    d.set_item("time_s", time_s)?;
    d.set_item("energy_J", energy)?;
    d.set_item("total_energy_J", s.total_energy())?;
    d.set_item("samples", s.samples())?;
    d.set_item("repeated_timestamps", s.repeated_timestamps())?;
    d.set_item("spikes", s.spikes())?;
    d.set_item("events_dropped", s.events_dropped())?;
    let faults = PyDict::new(py);
    for (name, n) in FaultCounts::CAUSES.iter().zip(s.faults().by_cause()) {
        faults.set_item(name, n)?;
    }
    d.set_item("faults", faults)?;
    d.set_item("max_slip_ratio", s.max_slip_ratio())?;
    d.set_item("max_axial_force_N", s.max_axial_force())?;
    d.set_item("min_margin_rad", s.min_margin())?;
    d.set_item("friction", m.friction())?;
    d.set_item("friction_baseline", m.friction_baseline())?;
    d.set_item("final_state", m.state().as_str())?;
    d.set_item("time_to_critical_s", m.time_to_critical())?;
    Ok(d)
}

/// The threshold planner (the monitor example's `--thresholds`): over loads up to
/// `up_to` (N; `None`: the configuration's `load_max`) or, given `trace_quantile`,
/// up to 1.2 times a trace's 99.9th percentile of load (N; `None` for a trace without
/// a finite load); `trace_load_max` the trace's operating range for the model choice,
/// as the replay makes it. Returns the rows, the range's top (N) and what was changed
/// from the range asked for (or None); a range the table cannot honour raises
/// ValueError.
#[pyfunction]
#[pyo3(signature = (scene, length, model, from_trace, top, trace_load_max, config=None))]
#[allow(clippy::too_many_arguments)]
fn thresholds(
    py: Python<'_>,
    scene: (f64, f64, f64, f64, f64),
    length: Option<f64>,
    model: &str,
    from_trace: bool,
    top: Option<f32>,
    trace_load_max: f64,
    config: Option<&Bound<'_, PyDict>>,
) -> PyResult<(Vec<[f64; 6]>, f32, Option<String>)> {
    let scene = scene_of(scene, length)?;
    let config = config_of(config)?;
    let choice = choice_for(&scene, trace_load_max)?;
    let range = if from_trace {
        output::PlanRange::Trace(top)
    } else {
        output::PlanRange::UpTo(top.unwrap_or(config.load_max))
    };
    let plan = match model {
        "f32" => {
            let core = Auto::with_choice(&scene, choice).map_err(value_error)?;
            py.detach(|| output::threshold_plan(&core, &config, range))
        }
        "fixed" => {
            let core = fixed_core(&scene, choice).map_err(value_error)?;
            py.detach(|| output::threshold_plan(&core, &config, range))
        }
        _ => {
            return Err(value_error(format!(
                "model must be 'f32' or 'fixed', not {model:?}"
            )));
        }
    }
    .map_err(value_error)?;
    Ok((plan.rows, plan.load_max, plan.note))
}

/// Where the reference's time goes per row, on one thread, for the demo scene over
/// the given loads (N) and angles (rad): ns per row of the reference's ellipse shape
/// (k', m, n from theta, eqs 4-6), its critical angle (phi0 at the load, eqs 18, 30),
/// its whole elliptic solution; of the fast path called row by row
/// (`reference::fast::Prepared::estimate`: d/b, F, phi0, flags; the batch takes it
/// sixteen rows at a time); and the batch as the package runs it on one thread (the
/// fast path plus writing the columns, through the AVX2 build where the CPU has it),
/// for one scene and for the same scene given on every row (a table of installations).
#[pyfunction]
fn reference_cost<'py>(
    py: Python<'py>,
    load: PyReadonlyArray1<'py, f64>,
    phi: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    use misalign::reference;
    use std::hint::black_box;
    use std::time::Instant;
    let (p, a) = (
        load.as_slice().map_err(value_error)?,
        phi.as_slice().map_err(value_error)?,
    );
    if p.len() != a.len() || p.is_empty() {
        return Err(value_error("load and phi: one non-empty length"));
    }
    let scene = Scene::DEMO;
    let n = p.len() as f64;
    let per_row = |f: &dyn Fn()| {
        let t = Instant::now();
        f();
        t.elapsed().as_secs_f64() * 1e9 / n
    };
    let figures = py.detach(|| {
        let shape = per_row(&|| {
            for &x in a {
                black_box(reference::normal::ellipse_shape(scene.auxiliary_angle(x)));
            }
        });
        let critical = per_row(&|| {
            for &x in p {
                black_box(reference::critical_angle(&scene, x));
            }
        });
        let elliptic = per_row(&|| {
            for (&x, &y) in p.iter().zip(a) {
                let _ = black_box(reference::elliptic(&scene, x, y));
            }
        });
        let fast = reference::fast::Prepared::new(&scene, reference::ModelChoice::Section9);
        let fast_estimate = per_row(&|| {
            if let Some(fast) = &fast {
                for (&x, &y) in p.iter().zip(a) {
                    black_box(fast.estimate(x, y));
                }
            }
        });
        let m = p.len();
        let (mut s, mut f, mut c) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let (mut r, mut mo, mut fl, mut st) =
            (vec![0u8; m], vec![0u8; m], vec![0u8; m], vec![0u8; m]);
        // The demo scene on every row, as a table of installations gives it.
        let each = [
            scene.r1(),
            scene.r2(),
            scene.shear_modulus(),
            scene.poisson_ratio(),
            scene.friction(),
        ]
        .map(|x| vec![x; m]);
        let per_row_scene = Inputs {
            r1: Column::Each(&each[0]),
            r2: Column::Each(&each[1]),
            shear_modulus: Column::Each(&each[2]),
            poisson_ratio: Column::Each(&each[3]),
            friction: Column::Each(&each[4]),
            length: None,
            load: Column::Each(p),
            phi: Column::Each(a),
            choice: reference::ModelChoice::Section9,
        };
        let one_scene = Inputs::one_scene(&scene, Column::Each(p), Column::Each(a));
        let mut timed_batch = |model: Model, inputs: &Inputs<'_>| {
            let t = Instant::now();
            let _ = rows_here(
                inputs,
                &mut Outputs {
                    slip_ratio: &mut s,
                    axial_force: &mut f,
                    critical_angle: &mut c,
                    regime: &mut r,
                    model: &mut mo,
                    flags: &mut fl,
                    status: &mut st,
                    details: None,
                },
                model,
            );
            t.elapsed().as_secs_f64() * 1e9 / n
        };
        let batch = timed_batch(Model::Reference, &one_scene);
        let f32_batch = timed_batch(Model::F32, &one_scene);
        let batch_rows = timed_batch(Model::Reference, &per_row_scene);
        let f32_batch_rows = timed_batch(Model::F32, &per_row_scene);
        let core = Auto::new(&scene);
        let f32_core = per_row(&|| {
            if let Ok(core) = &core {
                for (&x, &y) in p.iter().zip(a) {
                    let _ = black_box(core.estimate(x as f32, y as f32));
                }
            }
        });
        // A scene per row pays its preparation on each row.
        let prepare_fast = per_row(&|| {
            for _ in p {
                black_box(reference::fast::Prepared::new(
                    black_box(&scene),
                    reference::ModelChoice::Section9,
                ));
            }
        });
        let prepare_f32 = per_row(&|| {
            for _ in p {
                let _ = black_box(Auto::new(black_box(&scene)));
            }
        });
        [
            shape,
            critical,
            elliptic,
            fast_estimate,
            batch,
            f32_core,
            f32_batch,
            prepare_fast,
            prepare_f32,
            batch_rows,
            f32_batch_rows,
        ]
    });
    let d = PyDict::new(py);
    for (name, x) in [
        "ellipse_shape",
        "critical_angle",
        "elliptic",
        "fast_estimate",
        "batch",
        "f32_core",
        "f32_batch",
        "prepare_fast",
        "prepare_f32",
        "batch_rows",
        "f32_batch_rows",
    ]
    .into_iter()
    .zip(figures)
    {
        d.set_item(name, x)?;
    }
    Ok(d)
}

/// The compiled half of `misalign`.
#[pymodule]
fn _misalign(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(error_messages, m)?)?;
    m.add_function(wrap_pyfunction!(estimate, m)?)?;
    m.add_function(wrap_pyfunction!(solve, m)?)?;
    m.add_function(wrap_pyfunction!(scenario_samples, m)?)?;
    m.add_function(wrap_pyfunction!(thresholds, m)?)?;
    m.add_function(wrap_pyfunction!(reference_cost, m)?)?;
    m.add_class::<Replay>()?;
    Ok(())
}
