//! The monitor example's input files (`cargo run --example monitor -- --scene ...
//! --trace ...`): the scene and a recorded trace (CSV).

use misalign::Scene;
use misalign::monitor::Sample;
use std::error::Error;
use std::io::Read;

type Res<T> = Result<T, Box<dyn Error>>;

/// The scene: a CSV header naming `R1,R2,G,nu,mu` and optionally `length` (any order)
/// and one row.
pub fn read_scene(file: impl Read) -> Res<Scene> {
    let mut reader = csv::Reader::from_reader(file);
    let headers = reader.headers()?.clone();
    let row = reader
        .records()
        .next()
        .ok_or("the scene file has no row")??;
    let get = |name: &str| -> Res<Option<f64>> {
        match headers.iter().position(|h| h.trim() == name) {
            Some(i) => Ok(Some(row.get(i).unwrap_or("").trim().parse::<f64>()?)),
            None => Ok(None),
        }
    };
    let need = |name: &str| -> Res<f64> {
        get(name)?.ok_or_else(|| format!("the scene file lacks column {name}").into())
    };
    let scene = Scene::new(
        need("R1")?,
        need("R2")?,
        need("G")?,
        need("nu")?,
        need("mu")?,
    )?;
    Ok(match get("length")? {
        Some(l) => scene.with_length(l)?,
        None => scene,
    })
}

/// A trace: columns `t` (s), `P` (N), `phi` (rad), optional `V` (m/s) and `F` (N).
/// `t` becomes the node's wrapping u32 ms counter; an unreadable value a NaN (a sensor
/// fault for the monitor), an empty optional cell "not measured".
pub fn read_trace(file: impl Read) -> Res<Vec<Sample>> {
    let mut reader = csv::Reader::from_reader(file);
    let headers = reader.headers()?.clone();
    let col = |name: &str| headers.iter().position(|h| h.trim() == name);
    let (t, p, phi) = match (col("t"), col("P"), col("phi")) {
        (Some(t), Some(p), Some(phi)) => (t, p, phi),
        _ => return Err("the trace needs columns t, P, phi".into()),
    };
    let (v, f) = (col("V"), col("F"));
    let mut samples = Vec::new();
    for (i, row) in reader.records().enumerate() {
        let row = row?;
        // An unreadable number becomes NaN: the monitor counts it as a sensor fault.
        let num = |j: usize| {
            row.get(j)
                .unwrap_or("")
                .trim()
                .parse::<f64>()
                .unwrap_or(f64::NAN)
        };
        let time_s = num(t);
        if !time_s.is_finite() {
            return Err(format!("row {}: t is not a number", i + 2).into());
        }
        // The node's free-running u32 ms counter.
        let time_ms = ((time_s * 1e3).round() as i64).rem_euclid(1 << 32) as u32;
        // An empty cell of an optional column: not measured this time.
        let optional = |j: Option<usize>| {
            j.filter(|&j| !row.get(j).unwrap_or("").trim().is_empty())
                .map(|j| num(j) as f32)
        };
        let mut s = Sample::new(time_ms, num(p) as f32, num(phi) as f32);
        s.speed = optional(v);
        s.axial_force = optional(f);
        samples.push(s);
    }
    Ok(samples)
}
