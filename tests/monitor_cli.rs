//! The monitor example (`misalign_cli::monitor`, which `cargo run --example monitor`
//! runs) and its input files (`misalign_cli::monitor_input`): scene and trace.

use misalign_cli::monitor;
use misalign_cli::monitor_input as input;
use proptest::strategy::Strategy;
use std::path::PathBuf;

#[test]
fn a_trace_becomes_samples_on_the_nodes_wrapping_clock() {
    let csv =
        "t,P,phi,V,F\n4294960,2000,1e-4,1.5,\n4294961.5,2100,-2e-4,,300\n4294967.3,2200,x,2,\n";
    let samples = input::read_trace(csv.as_bytes()).unwrap();
    assert_eq!(samples.len(), 3);
    assert_eq!(
        (
            samples[0].time_ms,
            samples[0].load,
            samples[0].speed,
            samples[0].axial_force
        ),
        (4_294_960_000, 2000.0, Some(1.5), None)
    );
    // An empty V is "not measured" (the nominal speed), not a fault.
    assert_eq!(
        (
            samples[1].time_ms,
            samples[1].phi,
            samples[1].speed,
            samples[1].axial_force
        ),
        (4_294_961_500, -2e-4, None, Some(300.0))
    );
    // 4294967.3 s is past 2^32 ms: the counter wraps; an unreadable angle is a NaN, which
    // the monitor counts as a sensor fault.
    assert_eq!(samples[2].time_ms, 4);
    assert!(samples[2].phi.is_nan());
}

#[test]
fn a_traces_fault_column_names_a_sensors_own_fault() {
    use misalign::monitor::{FaultKind, SensorFault, SensorId};
    let csv = "t,P,phi,V,fault\n0,2000,1e-4,1.5,\n0.1,0,1e-4,1.5,load:disconnected\n\
               0.2,2000,0,,probe2:out_of_range\n0.3,2000,1e-4,1.5,probe3:stuck\n";
    let samples = input::read_trace(csv.as_bytes()).unwrap();
    let faults: Vec<Option<SensorFault>> = samples.iter().map(|s| s.sensor_fault).collect();
    let fault = |sensor, kind| Some(SensorFault { sensor, kind });
    assert_eq!(
        faults[..3],
        [
            None,
            fault(SensorId::Load, FaultKind::Disconnected),
            fault(SensorId::Probe2, FaultKind::OutOfRange)
        ]
    );
    // A fault this reader does not know: the row's values are no measurement.
    assert_eq!(faults[3], None);
    assert!(samples[3].load.is_nan());
    for sensor in SensorId::ALL {
        for kind in FaultKind::ALL {
            let cell = format!("{}:{}", sensor.name(), input::fault_kind_name(kind));
            assert_eq!(
                input::sensor_fault(cell.as_bytes()),
                Some(SensorFault { sensor, kind })
            );
        }
    }
}

#[test]
fn a_trace_without_its_columns_is_refused() {
    assert!(input::read_trace("t,P\n0,1\n".as_bytes()).is_err());
    assert!(input::read_trace("".as_bytes()).is_err());
}

/// A row without a usable time is skipped, and the rows around it are read.
#[test]
fn an_unreadable_row_is_skipped_not_the_end() {
    let mut csv = b"t,P,phi\n0,2000,1e-4\n".to_vec();
    csv.extend_from_slice(b"1,20\xff0,1e-4\n"); // not UTF-8 in P: a fault at t = 1
    csv.extend_from_slice(b"2,2000\n3,2000,1e-4,7\n,2000,1e-4\nnan,2000,1e-4\n\"4,2000,1e-4\n");
    csv.extend_from_slice(b"5,2000,1e-4\n");
    let samples = input::read_trace(&csv[..]).unwrap();
    let times: Vec<u32> = samples.iter().map(|s| s.time_ms).collect();
    assert_eq!(times, [0, 1000, 5000]);
    assert!(samples[1].load.is_nan());
    let mut trace = input::Trace::new(&csv[..]).unwrap();
    assert_eq!(trace.by_ref().count(), 3);
    let skipped = trace.skipped();
    assert_eq!(skipped.count, 5);
    let rows: Vec<u64> = skipped.first.iter().map(|r| r.0).collect();
    assert_eq!(rows, [4, 5, 6, 7, 8]);
    assert_eq!(trace.unreadable().first, [(3, "P: not UTF-8".to_string())]);
}

/// A time the monitor's millisecond clock cannot hold is refused, naming the row and
/// the likely unit, not saturated into repeated timestamps.
#[test]
fn a_time_beyond_the_clock_is_refused_with_its_unit() {
    let ns = "t,P,phi\n1.7e18,2000,1e-4\n1.700000001e18,2000,1e-4\n";
    let e = input::read_trace(ns.as_bytes()).unwrap_err().to_string();
    assert!(e.starts_with("row 2: t = 1.7e18 s is beyond"), "{e}");
    assert!(e.contains("is t in ns"), "{e}");
    let us = "t,P,phi\n1.7e15,2000,1e-4\n";
    let e = input::read_trace(us.as_bytes()).unwrap_err().to_string();
    assert!(e.contains("is t in us"), "{e}");
    let mut clock = input::TraceClock::new();
    assert_eq!(clock.time_ms(-1.0), Ok(u32::MAX - 999));
    assert!(clock.time_ms(f64::NAN).is_err());
}

/// A step the wrapping u32 counter would take modulo 2^32 ms (a year ahead becomes
/// days, or a step back) is refused; 2^31 ms - 1 ms is the longest step taken.
#[test]
fn a_step_beyond_the_wrapping_counter_is_refused() {
    let year = "t,P,phi\n0,2000,1e-4\n1,2000,1e-4\n31557600,2000,1e-4\n";
    let e = input::read_trace(year.as_bytes()).unwrap_err().to_string();
    assert!(
        e.starts_with("row 4: t steps forward by 3.1557599e7 s (365.2 days)"),
        "{e}"
    );
    let back = "t,P,phi\n5000000,2000,1e-4\n0,2000,1e-4\n";
    let e = input::read_trace(back.as_bytes()).unwrap_err().to_string();
    assert!(e.starts_with("row 3: t steps back"), "{e}");
    let mut clock = input::TraceClock::new();
    clock.time_ms(-1.0).unwrap();
    assert_eq!(clock.time_ms(2_147_482.647), Ok((1 << 31) - 1001));
    assert!(clock.time_ms(-1.001).is_err());
    // Times within the counter's range are the counter: a wrap goes on, as on the node.
    let wrap = "t,P,phi\n4294966,2000,1e-4\n4294967.2,2000,1e-4\n0.8,2000,1e-4\n";
    let times: Vec<u32> = input::read_trace(wrap.as_bytes())
        .unwrap()
        .iter()
        .map(|s| s.time_ms)
        .collect();
    assert_eq!(times, [4_294_966_000, 4_294_967_200, 800]);
}

/// The estimator's rules: a repeated column is named, a ';'-separated file is read
/// so, a bad scene number names its column and row.
#[test]
fn the_files_are_read_by_the_estimators_rules() {
    let e = input::read_trace("t,P,phi,phi\n0,1,2,3\n".as_bytes())
        .unwrap_err()
        .to_string();
    assert!(e.contains("column phi appears 2 times"), "{e}");
    let e = input::read_scene("R1,R2,G,nu,mu,mu\n0.05,0.05,79.3e9,0.3,0.3,0.2\n".as_bytes())
        .unwrap_err()
        .to_string();
    assert!(e.contains("column mu appears 2 times"), "{e}");
    let samples = input::read_trace("t;P;phi\n0;2000;1e-4\n1;2000;2e-4\n".as_bytes()).unwrap();
    assert_eq!((samples.len(), samples[1].phi), (2, 2e-4));
    let (scene, delimiter) =
        input::scene_and_delimiter("R1;R2;G;nu;mu\n0.05;0.05;79.3e9;0.3;0.3\n".as_bytes()).unwrap();
    assert_eq!((scene.r1(), delimiter), (0.05, b';'));
    let e = input::read_scene("R1,R2,G,nu,mu\n0.05,5 cm,79.3e9,0.3,0.3\n".as_bytes())
        .unwrap_err()
        .to_string();
    assert_eq!(e, "row 2: R2: not a number: \"5 cm\"");
    let e = input::read_scene("R1,R2,G,nu,mu\n0.05,0.05,79.3e9,0.3\n".as_bytes())
        .unwrap_err()
        .to_string();
    assert_eq!(e, "row 2: row has 4 fields, the header 5");
}

#[test]
fn a_scene_file_gives_the_scene_with_its_length() {
    let scene =
        input::read_scene("mu,nu,G,R2,R1,length\n0.3,0.3,79.3e9,inf,0.05,0.02\n".as_bytes())
            .unwrap();
    assert!(scene.is_plane());
    assert_eq!(
        (scene.r1(), scene.friction(), scene.length()),
        (0.05, 0.3, Some(0.02))
    );
    assert!(input::read_scene("R1,R2,G,nu\n0.05,0.05,79.3e9,0.3\n".as_bytes()).is_err());
    assert!(input::read_scene("R1,R2,G,nu,mu\n0.05,0.05,79.3e9,0.7,0.3\n".as_bytes()).is_err());
}

/// A trace file in a fresh directory of the target's.
fn trace_file(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("monitor_cli");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The monitor example on `args`: exit code, stdout, stderr.
fn monitor(args: &[&str]) -> (i32, String, String) {
    let args: Vec<String> = args.iter().map(|a| a.to_string()).collect();
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = monitor::run(&args, &mut out, &mut err, false);
    let text = |b: Vec<u8>| String::from_utf8(b).unwrap();
    (code, text(out), text(err))
}

/// One bad row in a trace: the replay goes on, prints its events and summary, counts
/// the row's fault or names the skipped row.
#[test]
fn the_replay_goes_on_past_bad_rows() {
    let mut csv = b"t,P,phi\n".to_vec();
    for i in 0..400 {
        let row = match i {
            10 => "10,2000,1e-4,5\n".to_string(),
            11 => "11,2000\n".to_string(),
            12 => ",2000,1e-4\n".to_string(),
            13 => "nan,2000,1e-4\n".to_string(),
            14 => "14,2000,\u{1}x\n".to_string(),
            // Gross slip late in the trace: an event after the bad rows.
            _ => format!(
                "{i},{},{}\n",
                2000 + i % 7 * 10,
                if i < 300 { 1e-4 } else { 3e-3 }
            ),
        };
        csv.extend_from_slice(row.as_bytes());
    }
    csv.extend_from_slice(b"400,2000,\xff\n");
    let path = trace_file("bad_rows.csv", &csv);
    let (code, out, err) = monitor(&["--trace", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("-> gross_slip"), "{out}");
    assert!(out.contains("\nsamples 397 "), "{out}");
    assert!(
        out.contains("trace rows skipped (no usable time) 4 (row 12: 4 fields, the header 3; row 13: 2 fields, the header 3; row 14: t: not a number: \"\"; row 15: t = NaN is not a time)"),
        "{out}"
    );
    assert!(
        out.contains("trace rows with a cell not a number (sensor faults) 2 (row 16: phi: not a number: \"\\u{1}x\"; row 402: phi: not UTF-8)"),
        "{out}"
    );
    assert!(err.contains("skipped 4 trace rows"), "{err}");
    let faults = out
        .lines()
        .find(|l| l.starts_with("faults "))
        .and_then(|l| l.split("non-finite ").nth(1))
        .and_then(|l| l.split(',').next())
        .unwrap();
    assert_eq!(faults, "2", "{out}");
}

/// `--model reference` replays on the f64 reference: over the built-in scenario the
/// f32 core (within 2.4e-7 of it) raises the same events at the same times, and the
/// readings they carry agree to the core's error.
#[test]
fn the_reference_replay_is_the_cores_events_without_their_rounding() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("monitor_cli");
    std::fs::create_dir_all(&dir).unwrap();
    let events = |model: &str| {
        let path = dir.join(format!("events-{model}.csv"));
        let (code, _, err) = monitor(&["--model", model, "--events", path.to_str().unwrap()]);
        assert_eq!(code, 0, "{err}");
        std::fs::read_to_string(path).unwrap()
    };
    let (reference, core) = (events("reference"), events("f32"));
    assert!(reference.lines().count() > 10, "{reference}");
    assert_eq!(reference.lines().count(), core.lines().count());
    for (r, c) in reference.lines().zip(core.lines()).skip(1) {
        let (r, c): (Vec<&str>, Vec<&str>) = (r.split(',').collect(), c.split(',').collect());
        // t, seq, state, from, kind, fault and time_ms: the same.
        assert_eq!((&r[..6], r[13]), (&c[..6], c[13]));
        // d/b (column s): the core's error, 2.4e-7 relative, on a monitor's reading.
        let s = |row: &[&str]| row[8].parse::<f64>().unwrap_or(0.0);
        assert!(
            (s(&r) - s(&c)).abs() <= 1e-6 * s(&r).abs().max(1e-3),
            "{r:?} {c:?}"
        );
    }
}

/// A trace in ns is refused before the replay, naming the row and the unit.
#[test]
fn a_trace_in_ns_is_refused_before_the_replay() {
    let csv: String = std::iter::once("t,P,phi\n".to_string())
        .chain((0..300).map(|i| {
            format!(
                "{},2000,1e-4\n",
                1_700_000_000_000_000_000u64 + i * 1_000_000_000
            )
        }))
        .collect();
    let path = trace_file("ns.csv", csv.as_bytes());
    let (code, out, err) = monitor(&["--trace", path.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(out.is_empty(), "{out}");
    assert!(err.contains("row 2: t = 1.7e18 s is beyond"), "{err}");
    assert!(err.contains("is t in ns"), "{err}");
}

/// `;`-separated files are read, and said to be; a repeated column refuses the trace.
#[test]
fn the_example_reads_semicolons_and_refuses_repeated_columns() {
    let scene = trace_file("scene.csv", b"R1;R2;G;nu;mu\n0.05;0.05;79.3e9;0.3;0.3\n");
    let trace = trace_file("semi.csv", b"t;P;phi\n0;2000;1e-4\n1;2010;1e-4\n");
    let (code, out, err) = monitor(&[
        "--scene",
        scene.to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("\nsamples 2 "), "{out}");
    assert!(
        err.contains("monitor: scene: the input is ';'-separated"),
        "{err}"
    );
    assert!(
        err.contains("monitor: trace: the input is ';'-separated"),
        "{err}"
    );
    let scene = trace_file("comma.csv", b"R1;R2;G;nu;mu\n0,05;0.05;79.3e9;0.3;0.3\n");
    let (code, _, err) = monitor(&["--scene", scene.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains("row 2: R1: not a number: \"0,05\""), "{err}");
    let trace = trace_file("twice.csv", b"t,P,P,phi\n0,1,2,3\n");
    let (code, out, err) = monitor(&["--trace", trace.to_str().unwrap()]);
    assert_eq!((code, out.as_str()), (1, ""));
    assert!(err.contains("column P appears 2 times"), "{err}");
}

#[test]
fn help_promises_what_the_reader_does() {
    let (code, out, _) = monitor(&["--help"]);
    assert_eq!(code, 0);
    assert!(!out.contains("anything unreadable a sensor fault"), "{out}");
    assert!(out.contains("is skipped"), "{out}");
}

proptest::proptest! {
    /// Whatever a row holds, the reader does not panic, and every row is a sample, a
    /// counted skipped row or blank, unless a time refuses the trace (naming its row).
    #[test]
    fn every_row_is_a_sample_or_counted(
        rows in proptest::collection::vec(
            proptest::prop_oneof![
                proptest::collection::vec(proptest::prelude::any::<u8>(), 0..24),
                "[0-9eE.,;\" naif+-]{0,24}".prop_map(String::into_bytes),
            ],
            0..24,
        )
    ) {
        let rows: Vec<Vec<u8>> = rows
            .into_iter()
            .map(|r| r.into_iter().filter(|&b| b != b'\n').collect())
            .collect();
        let mut csv = b"t,P,phi,V\n".to_vec();
        for r in &rows {
            csv.extend_from_slice(r);
            csv.push(b'\n');
        }
        let mut trace = input::Trace::new(&csv[..]).unwrap();
        let mut samples = 0u64;
        for s in trace.by_ref() {
            match s {
                Ok(_) => samples += 1,
                Err(e) => {
                    proptest::prop_assert!(e.starts_with("row "), "{}", e);
                    return Ok(());
                }
            }
        }
        let blank = rows.iter().filter(|r| r.iter().all(u8::is_ascii_whitespace)).count();
        proptest::prop_assert_eq!(samples + trace.skipped().count + blank as u64, rows.len() as u64);
    }
}

/// The peak resident memory (kB) of a replay of `rows` rows with every output, in a
/// child process: this test binary running `replay_child` alone.
#[cfg(target_os = "linux")]
fn peak_kb(rows: u64) -> u64 {
    let out = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["--exact", "replay_child", "--ignored", "--nocapture"])
        .env("MONITOR_CHILD_ROWS", rows.to_string())
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    text.lines()
        .find_map(|l| l.strip_prefix("peak_kb "))
        .and_then(|kb| kb.trim().parse().ok())
        .unwrap_or_else(|| panic!("no peak in {text}"))
}

/// Memory flat in the trace's length: four times the rows, with --plot, --thresholds
/// and --events, costs less than 4 MB more at the peak (keeping every sample and plot
/// point, some 70 B a row, would cost 10 MB more).
#[cfg(target_os = "linux")]
#[test]
fn the_replays_memory_does_not_grow_with_the_trace() {
    let (short, long) = (peak_kb(50_000), peak_kb(200_000));
    assert!(
        long < short + 4096,
        "{short} kB for 5e4 rows, {long} kB for 2e5"
    );
}

#[cfg(target_os = "linux")]
#[test]
#[ignore = "run in a child process by the_replays_memory_does_not_grow_with_the_trace"]
fn replay_child() {
    use std::io::Write;
    // Run alone (--include-ignored), a short replay.
    let rows: u64 = std::env::var("MONITOR_CHILD_ROWS").map_or(1000, |r| r.parse().unwrap());
    let trace = trace_file(&format!("long-{rows}.csv"), b"");
    let mut w = std::io::BufWriter::new(std::fs::File::create(&trace).unwrap());
    writeln!(w, "t,P,phi,V,F").unwrap();
    for i in 0..rows {
        let x = i as f64;
        let phi = 1e-4 + 6e-4 * (x / rows as f64);
        let p = 2500.0 + 40.0 * (x * 0.01).sin();
        writeln!(w, "{i},{p:.2},{phi:.4e},2.0,{:.1}", 0.15 * p).unwrap();
    }
    w.into_inner().unwrap().sync_all().unwrap();
    let dir = trace.parent().unwrap();
    let out = |name: &str| dir.join(format!("{rows}-{name}")).display().to_string();
    let args = [
        "--trace".to_string(),
        trace.display().to_string(),
        "--plot".into(),
        out("plot.svg"),
        "--thresholds".into(),
        out("thresholds.csv"),
        "--events".into(),
        out("events.csv"),
    ];
    let code = monitor::run(&args, &mut std::io::sink(), &mut std::io::sink(), false);
    assert_eq!(code, 0);
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let peak = status.lines().find(|l| l.starts_with("VmHWM:")).unwrap();
    println!(
        "peak_kb {}",
        peak.trim_start_matches("VmHWM:")
            .trim_end_matches("kB")
            .trim()
    );
}

/// The texts of an SVG's `<text>` elements, in document order.
fn svg_texts(svg: &str) -> Vec<String> {
    svg.split("<text ")
        .skip(1)
        .filter_map(|t| Some(t[t.find('>')? + 1..t.find("</text>")?].trim().to_string()))
        .collect()
}

/// The monitor's figures read as a figure should: a title, a legend for every kind of
/// line, horizontal axis titles (no rotated text), tick labels with the decimals their
/// step needs and no `-0`; on the planner's figure phi0 drawn over the "alarm raised"
/// curve it coincides with at the default alarm (d/b = 1).
#[test]
fn the_figures_have_titles_legends_and_clean_ticks() {
    let plot = trace_file("figure.svg", b"");
    let table = trace_file("figure-thresholds.csv", b"");
    let (code, _, err) = monitor(&[
        "--plot",
        plot.to_str().unwrap(),
        "--thresholds",
        table.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let timeline = std::fs::read_to_string(&plot).unwrap();
    let planner = std::fs::read_to_string(plot.with_file_name("figure-thresholds.svg")).unwrap();
    for (svg, title, legend) in [
        (
            &timeline,
            "Condition monitor over the built-in 8 h scenario",
            &["a state change", "warning and alarm thresholds"][..],
        ),
        (
            &planner,
            "Where each state is raised and cleared, over the load range",
            &["alarm raised", "phi0: gross slip (d/b = 1)"][..],
        ),
    ] {
        let texts = svg_texts(svg);
        assert!(texts.iter().any(|t| t == title), "no title {title}");
        for entry in legend {
            assert!(
                texts.iter().any(|t| t.starts_with(entry)),
                "no legend entry {entry}"
            );
        }
        assert!(!svg.contains("rotate("), "rotated text");
        for t in &texts {
            let number = t.parse::<f64>();
            assert!(
                !(number.is_ok() && t.starts_with("-0") && number == Ok(0.0)),
                "tick `{t}`"
            );
            // 300, 1100: no decimals where the step is whole.
            assert!(
                !(number.is_ok() && t.trim_end_matches('0').ends_with('.') && t.len() > 4),
                "tick `{t}` carries decimals its step does not need"
            );
        }
    }
    let alarm = planner
        .find(r##"stroke="#D55E00""##)
        .expect("the alarm raised curve");
    let phi0 = planner
        .find(r##"stroke="#000000" stroke-width="2""##)
        .unwrap();
    assert!(phi0 > alarm, "phi0 is drawn under the alarm raised curve");
}

/// `--thresholds` over a trace whose loads never reach above the stop load (100 N) is
/// refused with a message, not a table for a range the trace never saw; a trace whose
/// loads pass the configuration's `load_max` gets a table up to it, and says so.
#[test]
fn the_planners_range_is_refused_or_its_change_said() {
    let rows = |p: f64| {
        let mut csv = String::from("t,P,phi\n");
        for i in 0..200 {
            csv += &format!("{i},{p},2e-4\n");
        }
        csv
    };
    let dir = trace_file("plan-dir-marker", b"")
        .parent()
        .unwrap()
        .to_owned();
    let out = |name: &str| dir.join(name).display().to_string();
    for (name, p) in [
        ("plan-50.csv", 50.0),
        ("plan-neg.csv", -100.0),
        ("plan-nan.csv", f64::NAN),
    ] {
        let trace = trace_file(name, rows(p).as_bytes());
        let thresholds = out(&format!("{name}-thresholds.csv"));
        let _ = std::fs::remove_file(&thresholds);
        let (code, _, err) = monitor(&[
            "--trace",
            trace.to_str().unwrap(),
            "--plot",
            &out(&format!("{name}.svg")),
            "--thresholds",
            &thresholds,
        ]);
        assert_eq!(code, 1, "{name}: {err}");
        assert!(err.contains("--thresholds:"), "{name}: {err}");
        assert!(
            err.contains("stop load") || err.contains("no finite load"),
            "{name}: {err}"
        );
        assert!(!std::path::Path::new(&thresholds).exists(), "{name}");
    }
    // Above the configuration's maximum load (50 kN): the table ends there, said.
    let trace = trace_file("plan-high.csv", rows(49_000.0).as_bytes());
    let thresholds = out("plan-high-thresholds.csv");
    let (code, _, err) = monitor(&[
        "--trace",
        trace.to_str().unwrap(),
        "--plot",
        &out("plan-high.svg"),
        "--thresholds",
        &thresholds,
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("ends at the configuration's load_max, 50000 N"),
        "{err}"
    );
    let table = std::fs::read_to_string(&thresholds).unwrap();
    let last = table.lines().last().unwrap();
    assert!(last.starts_with("50000,"), "{last}");
}

/// `--thresholds` alone writes the planner's table (the web console and the Python
/// package give the table without a figure too), the same bytes as beside a plot.
#[test]
fn the_thresholds_table_needs_no_plot() {
    let dir = trace_file("alone-dir-marker", b"")
        .parent()
        .unwrap()
        .to_owned();
    let out = |name: &str| dir.join(name).display().to_string();
    let alone = out("alone-thresholds.csv");
    let (code, _, err) = monitor(&["--thresholds", &alone]);
    assert_eq!(code, 0, "{err}");
    let with_plot = out("with-plot-thresholds.csv");
    let (code, _, err) = monitor(&["--plot", &out("with-plot.svg"), "--thresholds", &with_plot]);
    assert_eq!(code, 0, "{err}");
    let table = std::fs::read(&alone).unwrap();
    assert!(
        table.starts_with(b"P,"),
        "{}",
        String::from_utf8_lossy(&table)
    );
    assert_eq!(table, std::fs::read(&with_plot).unwrap());
}
