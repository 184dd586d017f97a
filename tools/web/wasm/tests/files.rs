//! The page's files are the monitor example's, byte for byte (the browser tests check
//! the built page the same way, through Chromium).

use misalign_cli::replay::Model;
use misalign_web::{events_text, thresholds_text};
use std::path::{Path, PathBuf};

/// The monitor example run in-process on `args`: the file it wrote.
fn example(args: &[&str], file: &Path) -> String {
    let args: Vec<String> = args.iter().map(|a| a.to_string()).collect();
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = misalign_cli::monitor::run(&args, &mut out, &mut err, false);
    assert_eq!(code, 0, "{}", String::from_utf8_lossy(&err));
    std::fs::read_to_string(file).unwrap()
}

/// The page's events and thresholds are the example's files, byte for byte, on every
/// model, for the built-in scenario and for a trace with bad rows and its own scene.
#[test]
fn the_pages_files_are_the_examples() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("web");
    std::fs::create_dir_all(&dir).unwrap();
    let mut trace = String::from("t,P,phi,V,F\n");
    for i in 0..3000 {
        let x = f64::from(i);
        let (p, phi) = (
            2500.0 + 40.0 * (x / 7.0).sin(),
            1e-4 + 9e-4 * (x / 600.0).sin(),
        );
        trace += &match i % 397 {
            5 => format!("{i},abc,{phi},2.0,\n"),
            17 => format!(",{p},{phi},2.0,\n"),
            33 => format!("{i},{p}\n"),
            99 => "\n".into(),
            _ => format!(
                "{i},{p},{phi},2.0,{}\n",
                if i % 3 == 0 { "120" } else { "" }
            ),
        };
    }
    let scene = "R1,R2,G,nu,mu,length\n0.06,0.04,79.3e9,0.3,0.25,0.5\n";
    let (trace_path, scene_path) = (dir.join("trace.csv"), dir.join("scene.csv"));
    std::fs::write(&trace_path, &trace).unwrap();
    std::fs::write(&scene_path, scene).unwrap();
    let (events, plot, table) = (dir.join("e.csv"), dir.join("p.svg"), dir.join("t.csv"));
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (events_s, trace_s, scene_s) = (s(&events), s(&trace_path), s(&scene_path));
    let (plot_s, table_s) = (s(&plot), s(&table));
    for model in ["f32", "fixed", "reference"] {
        let m = Model::parse(model).unwrap();
        let base = ["--model", model, "--events", &events_s];
        let builtin = example(&base, &events);
        assert!(builtin.lines().count() > 10, "{builtin}");
        assert_eq!(events_text(None, None, m).unwrap(), builtin, "{model}");
        let with = [&base[..], &["--trace", &trace_s, "--scene", &scene_s]].concat();
        let file = example(&with, &events);
        assert!(file.lines().count() > 3, "{file}");
        assert_eq!(
            events_text(Some(trace.as_bytes()), Some(scene), m).unwrap(),
            file
        );
        let planned = [&with[..], &["--plot", &plot_s, "--thresholds", &table_s]].concat();
        let file = example(&planned, &table);
        assert_eq!(
            thresholds_text(Some(trace.as_bytes()), Some(scene), m).unwrap(),
            file
        );
    }
}

/// A bad file says what is wrong, naming the file's part.
#[test]
fn bad_files_are_refused_with_a_reason() {
    let e = events_text(Some(b"time,P\n1,2\n"), None, Model::F32).unwrap_err();
    assert!(e.starts_with("trace: ") && e.contains("phi"), "{e}");
    let e = events_text(None, Some("R1,R2\n1,2\n"), Model::F32).unwrap_err();
    assert!(e.starts_with("scene: ") && e.contains("G"), "{e}");
    let e = events_text(Some(b"t,P,phi\n0,1,1e-4\n1e20,1,1e-4\n"), None, Model::F32).unwrap_err();
    assert!(e.contains("row 3"), "{e}");
}
