//! The CSV estimator (examples/estimate) reproduces the reference data files row by
//! row within 1e-12 relative, and handles bad rows and bad input as documented.

#[path = "../examples/estimate/cli.rs"]
mod cli;
mod common;

use common::{Row, Worst, num, read_rows, reference_dir};

fn run(args: &[&str], input: &[u8]) -> (i32, String, String) {
    let args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = cli::run(&args, input, &mut out, &mut err);
    (
        code,
        String::from_utf8(out).unwrap(),
        String::from_utf8(err).unwrap(),
    )
}

fn parse(text: &str) -> Vec<Row> {
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let headers = reader.headers().unwrap().clone();
    reader
        .records()
        .map(|r| {
            r.unwrap()
                .iter()
                .zip(headers.iter())
                .map(|(v, h)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

fn reproduce(file: &str, contact: &str, columns: &[&str]) {
    reproduce_with("reference", file, contact, columns, 1e-12);
}

fn reproduce_with(model: &str, file: &str, contact: &str, columns: &[&str], bound: f64) {
    let input = std::fs::read(reference_dir().join(file)).unwrap();
    let (code, out, err) = run(&["--model", model, "--contact", contact], &input);
    assert_eq!(code, 0, "{err}");
    let want = read_rows(file);
    let got = parse(&out);
    assert_eq!(got.len(), want.len());
    let mut worst = Worst::default();
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        assert_eq!(g["error"], "", "row {i}");
        // Only the reference is exact at d/b = 1; the cores may differ within their
        // error of it (issue 3: 1e-6 for f32; the same window for fixed).
        if model == "reference" || (num(w, "s") - 1.0).abs() > 1e-6 {
            assert_eq!(g["regime"], w["regime"], "row {i}");
        }
        for c in columns {
            worst.add(c, i, num(g, c), num(w, c));
        }
    }
    worst.assert_below(bound);
}

#[test]
fn reproduces_vectors_scene() {
    reproduce(
        "vectors_scene.csv",
        "elliptic",
        &[
            "theta", "m", "n", "a", "b", "p0", "s", "F", "phi0", "kprime", "Pstar", "P0star",
            "theta0", "d",
        ],
    );
}

#[test]
fn reproduces_vectors_line() {
    reproduce(
        "vectors_line.csv",
        "line",
        &["R", "b", "p0", "s", "F", "phi0", "Pstar", "P0star", "d"],
    );
}

/// The cores through the same tool: issue 3's targets (f32 2e-6, fixed 1e-4); the
/// regime may differ from the reference only near d/b = 1, which the data avoid.
#[test]
fn cores_reproduce_the_reference_files() {
    let elliptic = ["theta", "m", "n", "a", "b", "p0", "s", "F", "phi0"];
    let line = ["s", "F", "phi0"];
    reproduce_with("f32", "vectors_scene.csv", "elliptic", &elliptic, 2e-6);
    reproduce_with("f32", "vectors_line.csv", "line", &line, 2e-6);
    reproduce_with("fixed", "vectors_scene.csv", "elliptic", &elliptic, 1e-4);
    reproduce_with("fixed", "vectors_line.csv", "line", &line, 1e-4);
}

#[test]
fn numbers_read_back_exactly() {
    for x in [
        0.0,
        1.0,
        -2.5e-300,
        1.0 / 3.0,
        123456.789,
        6.02e23,
        f64::MIN_POSITIVE,
        f64::MAX,
        1e-3,
        9.999e6,
    ] {
        assert_eq!(cli::number(x).parse::<f64>().unwrap(), x);
    }
    assert_eq!(cli::number(f64::INFINITY), "inf");
}

#[test]
fn bad_rows_get_messages_and_the_batch_goes_on() {
    let input = b"note,phi,P,mu,nu,G,R2,R1\n\
        ok,1e-3,100,0.3,0.3,8e10,inf,0.02\n\
        nan angle,NaN,100,0.3,0.3,8e10,0.02,0.02\n\
        text,abc,100,0.3,0.3,8e10,0.02,0.02\n\
        neg load,1e-3,-1,0.3,0.3,8e10,0.02,0.02\n\
        ok,1e-3,100,0.3,0.3,8e10,0.02,0.02\n";
    let (code, out, _) = run(&[], input);
    assert_eq!(code, 0);
    let rows = parse(&out);
    assert_eq!(rows.len(), 5);
    assert!(rows[0]["error"].contains("plane"), "{:?}", rows[0]);
    assert!(rows[1]["error"].contains("phi"));
    assert!(rows[2]["error"].contains("not a number"));
    assert!(rows[3]["error"].contains("load"));
    assert_eq!(rows[3]["s"], "");
    assert_eq!(rows[4]["error"], "");
    assert!(num(&rows[4], "s") > 0.0);
    // The plane row is fine for line contact.
    let (_, out, _) = run(&["--contact", "line"], input);
    assert_eq!(parse(&out)[0]["error"], "");
}

#[test]
fn not_csv_or_missing_column_is_an_exit_code() {
    let (code, _, err) = run(&[], b"R1,R2,G,nu,mu,P\n1,1,1,0.3,0.3,1\n");
    assert_ne!(code, 0);
    assert!(err.contains("phi"));
    let (code, _, err) = run(&[], b"R1,R2,G,nu,mu,P,phi\n1,1,1,0.3\n");
    assert_ne!(code, 0);
    assert!(err.contains("not CSV"));
    let (code, _, _) = run(&["--model", "bogus"], b"");
    assert_eq!(code, 2);
    let (code, out, _) = run(&["--help"], b"");
    assert_eq!(code, 0);
    assert!(out.contains("--contact"));
}

#[test]
fn default_example_runs_clean() {
    let input = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/data/default.csv"
    ))
    .unwrap();
    let (code, out, _) = run(&["--model", "reference"], &input);
    assert_eq!(code, 0);
    let rows = parse(&out);
    assert_eq!(rows.len(), 9);
    assert!(rows.iter().filter(|r| !r["error"].is_empty()).count() == 1);
    assert!(
        rows.iter()
            .any(|r| r["flags"].contains("longer_than_rollers"))
    );
}
