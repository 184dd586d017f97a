//! `estimate --solve mu|phi`: the CSV layer over the inverses. The
//! estimator's forward mode, then its inverse, recovers mu and phi over the public
//! reference scenes within the library's bounds (1e-12 reference, 2e-6 f32, times the
//! sensitivity where it exceeds 1, wherever it is below 1e3), says `at_least` exactly
//! where the forward map saturates, and turns bad rows into their `error`.

use misalign_cli::estimate as cli;
mod common;

use common::{Row, num, read_rows, rel_err};

/// Runs the estimator; the exit code, stdout and stderr.
fn run_text(args: &[&str], input: &str) -> (i32, String, String) {
    let args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = cli::run(&args, input.as_bytes(), &mut out, &mut err);
    let text = |b: Vec<u8>| String::from_utf8(b).unwrap();
    (code, text(out), text(err))
}

/// Runs the estimator; the exit code, the output's header and rows, and stderr.
fn run(args: &[&str], input: &str) -> (i32, Vec<String>, Vec<Vec<String>>, String) {
    let (code, out, err) = run_text(args, input);
    let mut reader = csv::Reader::from_reader(out.as_bytes());
    let header = match reader.headers() {
        Ok(h) => h.iter().map(String::from).collect(),
        Err(_) => Vec::new(),
    };
    let rows = reader
        .records()
        .map(|r| r.unwrap().iter().map(String::from).collect())
        .collect();
    (code, header, rows, err)
}

const COLUMNS: [&str; 7] = ["R1", "R2", "G", "nu", "mu", "P", "phi"];

/// The fields of a row of a reference file that the estimator reads; with `lengths`, a
/// length of twice or half the ellipse's 2a (every other row), so that section 9
/// takes line contact on half the rows.
fn fields(row: &Row, i: usize, lengths: bool) -> String {
    let mut text = COLUMNS.map(|k| row[k].as_str()).join(",");
    if lengths {
        let scale = if i.is_multiple_of(2) { 4.0 } else { 1.0 };
        text += &format!(",{:e}", scale * num(row, "a"));
    }
    text
}

/// Forward through the estimator, then `--solve mu` and `--solve phi` on its F, all
/// with `model` and `contact`; checks every row against the forward inputs.
fn round_trip(model: &str, file: &str, contact: &str, lengths: bool, bound: f64) {
    let rows = read_rows(file);
    let names = COLUMNS.join(",") + if lengths { ",length" } else { "" };
    let mut input = names.clone() + "\n";
    for (i, row) in rows.iter().enumerate() {
        input += &(fields(row, i, lengths) + "\n");
    }
    let (code, header, forward, err) = run(&["--model", model, "--contact", contact], &input);
    assert_eq!(code, 0, "{err}");
    let at = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (f_at, regime_at, error_at) = (at("F"), at("regime"), at("error"));
    // The inverse's input: the forward input with F; the unknown's column is ignored.
    let mut solve_input = names + ",F\n";
    let mut models = [0; 2];
    for (i, (row, out)) in rows.iter().zip(&forward).enumerate() {
        assert_eq!(out[error_at], "", "{row:?}");
        models[usize::from(out[at("model")] == "line")] += 1;
        solve_input += &format!("{},{}\n", fields(row, i, lengths), out[f_at]);
    }
    if lengths {
        assert_eq!(models, [rows.len() / 2; 2]);
    }
    let solve = |unknown: &str| {
        let args = ["--model", model, "--contact", contact, "--solve", unknown];
        let (code, header, answers, err) = run(&args, &solve_input);
        assert_eq!(code, 0, "{err}");
        assert_eq!(header, [unknown, "bound", "sensitivity", "error"]);
        assert_eq!(answers.len(), rows.len());
        answers
    };
    let within = |got: f64, want: f64, sensitivity: &str| {
        let s: f64 = sensitivity.parse().unwrap();
        assert!(s >= 0.0, "sensitivity {s}");
        s >= 1e3 || rel_err(got, want) <= bound * s.max(1.0)
    };
    // mu: exact wherever F depends on it (mu = F/P in gross slip); at phi = 0, F = 0 for
    // every mu; at_least where F is within rounding of its no-slip limit, which only
    // a tiny slip ratio reaches (S ~ pi / (2 s) beyond 1e3 there).
    let s_at = at("s");
    for (i, ((row, out), answer)) in rows.iter().zip(&forward).zip(&solve("mu")).enumerate() {
        if num(row, "phi") == 0.0 {
            assert_eq!(answer, &["0.0", "at_least", "", ""], "row {i}");
            continue;
        }
        if answer[1] == "at_least" {
            let s: f64 = out[s_at].parse().unwrap();
            assert!(s < 1e-3, "row {i}: {answer:?} at s = {s}");
            let mu: f64 = answer[0].parse().unwrap();
            assert!(mu <= num(row, "mu") * (1.0 + bound), "row {i}: {answer:?}");
            continue;
        }
        assert_eq!(answer[1], "exact", "row {i}: {answer:?}");
        assert_eq!(answer[3], "", "row {i}");
        let mu: f64 = answer[0].parse().unwrap();
        let want = num(row, "mu");
        assert!(
            within(mu, want, &answer[2]),
            "row {i}: {answer:?} vs {want}"
        );
    }
    // phi: at_least phi0 exactly where the forward map saturates: in gross slip, and
    // where partial slip so close to s = 1 gives mu P to the last bits (line contact:
    // 1 - F/(mu P) = (1 - s)^2).
    let mut counts = [0; 2];
    for (i, ((row, out), answer)) in rows.iter().zip(&forward).zip(&solve("phi")).enumerate() {
        let phi: f64 = answer[0].parse().unwrap();
        let want = num(row, "phi");
        assert_eq!(phi.signum(), want.signum(), "row {i}: {answer:?}");
        assert_eq!(answer[3], "", "row {i}");
        let f: f64 = out[f_at].parse().unwrap();
        let saturated = rel_err(f.abs(), num(row, "mu") * num(row, "P")) <= bound;
        if out[regime_at] == "gross" || (saturated && answer[1] == "at_least") {
            assert_eq!(answer[1..3], ["at_least", ""], "row {i}: {answer:?}");
            // The bound is the forward's phi0; section 9 may give a smaller one, where
            // the other model saturates at a smaller phi that it would choose.
            let phi0: f64 = out[at("phi0")].parse().unwrap();
            let tight = rel_err(phi.abs(), phi0) <= bound;
            let below = phi.abs() <= phi0 * (1.0 + bound);
            assert!(
                tight || (below && contact == "auto"),
                "row {i}: {answer:?} vs {phi0}"
            );
            counts[1] += 1;
        } else {
            assert_eq!(answer[1], "exact", "row {i}: {answer:?} {out:?}");
            assert!(
                within(phi, want, &answer[2]),
                "row {i}: {answer:?} vs {want}"
            );
            counts[0] += 1;
        }
    }
    assert!(counts.iter().all(|&n| n > rows.len() / 10), "{counts:?}");
}

/// The reference files, each with the contact models it exercises: the ellipse, section
/// 9 switching to line contact on half the rows (with lengths), line contact.
const CASES: [(&str, &str, bool); 3] = [
    ("vectors_scene.csv", "elliptic", false),
    ("vectors_scene.csv", "auto", true),
    ("vectors_line.csv", "line", false),
];

#[test]
fn reference_round_trips() {
    for (file, contact, lengths) in CASES {
        round_trip("reference", file, contact, lengths, 1e-12);
    }
}

#[test]
fn f32_round_trips() {
    for (file, contact, lengths) in CASES {
        round_trip("f32", file, contact, lengths, 2e-6);
    }
}

const BAD_MU_ROWS: &str = "R1,R2,G,nu,P,phi,F\n\
                           0.05,0.05,8e10,0.3,1000,2e-4,NaN\n\
                           0.05,0.05,8e10,0.3,1000,2e-4,-1\n\
                           0.05,0.05,8e10,0.3,0,2e-4,1\n\
                           0.05,0.05,8e10,0.3,1000,0,1\n\
                           0.05,0.05,8e10,0.3,1000,2e-4,1e9\n\
                           0.05,0.05,8e10,0.3,1000,2e-4,x\n\
                           0.05,0.05,8e10,0.3,1000,2e-4\n\
                           0.05,0.05,8e10,0.3,1000,2e-4,inf\n\
                           0.05,0.05,8e10,0.3,1000,1e-2,100\n";

#[test]
fn bad_rows_become_their_error() {
    for model in ["reference", "f32"] {
        let (code, _, out, err) = run(&["--model", model, "--solve", "mu"], BAD_MU_ROWS);
        assert_eq!((code, err.as_str()), (0, ""));
        assert_eq!(out[0], ["", "", "", "axial force F must be finite"]);
        assert_eq!(out[1], ["", "inconsistent", "", "opposite_sign"]);
        assert_eq!(out[2], ["", "inconsistent", "", "zero_load"]);
        assert_eq!(out[3], ["", "inconsistent", "", "no_misalignment"]);
        assert_eq!(out[4], ["", "inconsistent", "", "above_model"]);
        assert_eq!(out[5][..3], ["", "", ""]);
        assert!(out[5][3].starts_with("F: not a number"), "{:?}", out[5]);
        assert_eq!(out[6][3], "row has 6 fields, the header 7");
        assert_eq!(out[7], ["", "", "", "axial force F must be finite"]);
        // The batch went on to the last row.
        assert_eq!(out[8], ["0.1", "exact", "1.0", ""], "{model}");
    }
    // A missing mu where the phi-inverse needs one: Scene::new's error.
    let (_, _, out, _) = run(
        &["--solve", "phi"],
        "R1,R2,G,nu,mu,P,F\n0.05,0.05,8e10,0.3,,1000,1\n0.05,0.05,8e10,0.3,0,1000,1\n",
    );
    assert!(out[0][3].starts_with("mu: not a number"), "{:?}", out[0]);
    assert_eq!(out[1][1], "");
    assert!(out[1][3].contains("mu"), "{:?}", out[1]);
}

#[test]
fn fixed_says_it_has_no_inverse_on_every_row() {
    let (code, _, out, _) = run(&["--model", "fixed", "--solve", "mu"], BAD_MU_ROWS);
    assert_eq!(code, 0);
    for row in out
        .iter()
        .filter(|r| !r[3].starts_with("F: not") && !r[3].starts_with("row"))
    {
        assert_eq!(row[..3], ["", "", ""]);
        assert!(row[3].contains("no inverse"), "{row:?}");
    }
    let (_, help, _) = run_text(&["--help"], "");
    assert!(
        help.contains("--model fixed answers every row with an error: the fixed-point core has no\n    inverse"),
        "{help}"
    );
    assert!(
        help.contains("placeholder\n        mu = 1, which the inverses do not read"),
        "{help}"
    );
}

#[test]
fn phi_is_signed_like_f_and_gross_slip_is_a_bound() {
    // Line contact, gross slip: F = mu P says only |phi| >= phi0, signed like F.
    let (_, _, out, _) = run(
        &["--solve", "phi", "--contact", "line"],
        "R1,R2,G,nu,mu,P,F\n0.05,inf,8e10,0.3,0.25,1000,-250\n",
    );
    assert_eq!(out[0][1..], ["at_least", "", ""]);
    assert!(out[0][0].parse::<f64>().unwrap() < 0.0);
    // A total P and F with a length are per unit length in line contact, as forward.
    let per_metre = "R1,R2,G,nu,mu,P,F\n0.05,0.05,8e10,0.3,0.25,1000,-100\n";
    let total = "R1,R2,G,nu,mu,P,F,length\n0.05,0.05,8e10,0.3,0.25,500,-50,0.5\n";
    for (model, bound) in [("reference", 1e-15), ("f32", 1e-6)] {
        let args = ["--model", model, "--contact", "line", "--solve", "phi"];
        let (a, b) = (&run(&args, per_metre).2[0], &run(&args, total).2[0]);
        assert_eq!((&a[1], &b[1]), (&"exact".to_string(), &"exact".to_string()));
        let x = |row: &[String], k: usize| row[k].parse::<f64>().unwrap();
        assert!(rel_err(x(a, 0), x(b, 0)) <= bound, "{a:?} {b:?}");
        assert!(rel_err(x(a, 2), x(b, 2)) <= bound, "{a:?} {b:?}");
    }
}

#[test]
fn header_errors_name_the_solve_columns() {
    let (code, _, _, err) = run(&["--solve", "phi"], "R1,R2,G,nu,P,F\n");
    assert_eq!(code, 1);
    assert!(err.contains("needs R1,R2,G,nu,mu,P,F"), "{err}");
    let (code, _, _, err) = run(&["--solve", "mu"], "R1,R2,G,nu,mu,P,F\n");
    assert_eq!(code, 1);
    assert!(
        err.contains("lacks column phi (needs R1,R2,G,nu,P,phi,F)"),
        "{err}"
    );
    // ';'-separated input is detected for the inverse's columns too.
    let (code, header, out, err) = run(
        &["--solve", "mu"],
        "R1;R2;G;nu;P;phi;F\n0.05;0.05;8e10;0.3;1000;1e-2;100\n",
    );
    assert_eq!(code, 0);
    assert!(err.contains("';'-separated"), "{err}");
    assert_eq!(header, ["mu", "bound", "sensitivity", "error"]);
    assert_eq!(out[0], ["0.1", "exact", "1.0", ""]);
    let (code, _, _, err) = run(&["--solve", "nu"], "");
    assert_eq!(code, 2, "{err}");
}

mod properties {
    use super::run;
    use proptest::prelude::*;

    /// A field: mostly a plausible value between 10^lo and 10^hi (signed when asked),
    /// sometimes one that no row should hold.
    fn field(lo: f64, hi: f64, signed: bool) -> impl Strategy<Value = String> {
        let plausible = (lo..hi, any::<bool>()).prop_map(move |(e, negative)| {
            let x = 10f64.powf(e);
            format!("{:e}", if signed && negative { -x } else { x })
        });
        let odd = prop_oneof![
            Just("0"),
            Just("-0"),
            Just("NaN"),
            Just("inf"),
            Just("-inf"),
            Just("-1"),
            Just("1e400"),
            Just("x"),
            Just(""),
        ]
        .prop_map(String::from);
        prop_oneof![8 => plausible, 1 => odd]
    }

    /// `R1,R2,G,nu,mu,phi,P,F,length` rows; each `--solve` reads its own seven columns
    /// (and the length) and ignores the rest.
    fn rows() -> impl Strategy<Value = Vec<String>> {
        let row = (
            field(-3.0, 0.0, false),
            prop_oneof![field(-3.0, 0.0, false), Just("inf".to_string())],
            field(9.0, 11.5, false),
            (0.0..0.5f64).prop_map(|nu| nu.to_string()),
            field(-3.0, 0.0, false),
            field(-9.0, 0.19, true),
            field(-2.0, 6.0, false),
            field(-8.0, 6.0, true),
            prop_oneof![field(-3.0, 0.5, false), Just(String::new())],
        )
            .prop_map(|(r1, r2, g, nu, mu, phi, p, f, l)| {
                [r1, r2, g, nu, mu, phi, p, f, l].join(",")
            });
        prop::collection::vec(row, 1..6)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Every model, contact and unknown: exit 0, one row per input row, and every
        /// answer in the physical range (mu >= 0, |phi| <= pi/2 signed like F,
        /// sensitivity >= 0), or an error that says why.
        #[test]
        fn never_panics_and_stays_physical(rows in rows()) {
            let input = format!("R1,R2,G,nu,mu,phi,P,F,length\n{}\n", rows.join("\n"));
            let forces: Vec<f64> = rows
                .iter()
                .map(|r| r.split(',').nth(7).unwrap().parse().unwrap_or(f64::NAN))
                .collect();
            for model in ["reference", "f32", "fixed"] {
                for contact in ["auto", "elliptic", "line"] {
                    for unknown in ["mu", "phi"] {
                        let args = ["--model", model, "--contact", contact, "--solve", unknown];
                        let (code, _, out, err) = run(&args, &input);
                        prop_assert_eq!(code, 0, "{}", err);
                        prop_assert_eq!(out.len(), rows.len());
                        for (answer, &f) in out.iter().zip(&forces) {
                            prop_assert_eq!(answer.len(), 4);
                            let value = answer[0].parse::<f64>();
                            match answer[1].as_str() {
                                "exact" | "at_least" => {
                                    let x = value.unwrap();
                                    prop_assert!(x.is_finite(), "{:?}", answer);
                                    if unknown == "mu" {
                                        prop_assert!(x >= 0.0, "{:?}", answer);
                                    } else {
                                        prop_assert!(x.abs() <= core::f64::consts::FRAC_PI_2);
                                        prop_assert!(x == 0.0 || x.signum() == f.signum());
                                    }
                                    if answer[1] == "exact" {
                                        let s: f64 = answer[2].parse().unwrap();
                                        prop_assert!(s >= 0.0, "{:?}", answer);
                                    } else {
                                        prop_assert_eq!(&answer[2], "");
                                    }
                                    prop_assert_eq!(&answer[3], "");
                                }
                                "inconsistent" | "" => {
                                    prop_assert_eq!(&answer[0], "");
                                    prop_assert_eq!(&answer[2], "");
                                    prop_assert!(!answer[3].is_empty(), "{:?}", answer);
                                }
                                other => prop_assert!(false, "bound {}", other),
                            }
                            if model == "fixed" && !answer[3].contains("no inverse") {
                                // Only a row the tool cannot read says something else.
                                prop_assert!(answer[1].is_empty(), "{:?}", answer);
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The mu-inverse reads phi as the f64 the file gives, in both models: the f64 above
/// f64's FRAC_PI_2 is refused, also by the f32 core, whose rounding would carry it onto
/// f32's FRAC_PI_2; f64's FRAC_PI_2 itself is inside the domain.
#[test]
fn the_mu_inverse_draws_the_right_angle_at_the_files_f64() {
    let half_pi = core::f64::consts::FRAC_PI_2;
    let input = format!(
        "R1,R2,G,nu,P,phi,F\n\
         0.05,0.05,8e10,0.3,1000,{half_pi:?},100\n\
         0.05,0.05,8e10,0.3,1000,{:?},100\n",
        half_pi.next_up()
    );
    for model in ["reference", "f32"] {
        let (code, _, out, err) = run(&["--model", model, "--solve", "mu"], &input);
        assert_eq!((code, err.as_str()), (0, ""), "{model}");
        assert!(!out[0][3].contains("pi/2"), "{model}: {:?}", out[0]);
        assert!(out[1][3].contains("|phi| <= pi/2"), "{model}: {:?}", out[1]);
    }
}
