//! `misalign::batch` against the independent 50-digit values of tests/data (the
//! reference over slices, a scene per row), against the cores called row by row (one
//! scene for all, a scene per row), and on bad rows and bad lengths.

mod common;
use common::{Worst, num, read_rows};
use misalign::batch::{self, Column, Counts, Details, Inputs, Mismatch, Model, Outputs};
use misalign::fixed::FixedAuto;
use misalign::float::Auto;
use misalign::reference::ModelChoice;
use misalign::{Error, Scene};

/// d/b, F and phi0 of the reference against the 50-digit values.
const MAIN_BOUND: f64 = 4e-15;
/// Every other column: the bound of tests/reference_vectors.rs.
const BOUND: f64 = 1e-12;

/// Owned output columns of `n` rows.
struct Owned {
    s: Vec<f64>,
    f: Vec<f64>,
    phi0: Vec<f64>,
    regime: Vec<u8>,
    model: Vec<u8>,
    flags: Vec<u8>,
    status: Vec<u8>,
    details: Vec<Vec<f64>>,
}

impl Owned {
    fn new(n: usize) -> Self {
        Owned {
            s: vec![0.0; n],
            f: vec![0.0; n],
            phi0: vec![0.0; n],
            regime: vec![0; n],
            model: vec![0; n],
            flags: vec![0; n],
            status: vec![0; n],
            details: vec![vec![0.0; n]; 12],
        }
    }

    fn outputs(&mut self, with_details: bool) -> Outputs<'_> {
        let details = if with_details {
            let [
                theta,
                kprime,
                m,
                n,
                a,
                b,
                p0,
                d,
                pstar,
                p0star,
                theta0,
                radius,
            ] = <&mut [Vec<f64>; 12]>::try_from(self.details.as_mut_slice()).unwrap();
            Some(Details {
                theta,
                kprime,
                m,
                n,
                a,
                b,
                p0,
                d,
                pstar,
                p0star,
                theta0,
                radius,
            })
        } else {
            None
        };
        Outputs {
            slip_ratio: &mut self.s,
            axial_force: &mut self.f,
            critical_angle: &mut self.phi0,
            regime: &mut self.regime,
            model: &mut self.model,
            flags: &mut self.flags,
            status: &mut self.status,
            details,
        }
    }

    fn detail(&self, name: &str) -> &[f64] {
        let names = [
            "theta", "kprime", "m", "n", "a", "b", "p0", "d", "Pstar", "P0star", "theta0", "R",
        ];
        &self.details[names.iter().position(|n| *n == name).unwrap()]
    }
}

fn column(rows: &[common::Row], name: &str) -> Vec<f64> {
    rows.iter().map(|r| num(r, name)).collect()
}

fn regime(code: u8) -> &'static str {
    ["partial", "gross"][code as usize]
}

/// A scene per row, from the columns of a reference file.
fn inputs<'a>(cols: &'a [Vec<f64>; 7], choice: ModelChoice) -> Inputs<'a> {
    Inputs {
        r1: Column::Each(&cols[0]),
        r2: Column::Each(&cols[1]),
        shear_modulus: Column::Each(&cols[2]),
        poisson_ratio: Column::Each(&cols[3]),
        friction: Column::Each(&cols[4]),
        length: None,
        load: Column::Each(&cols[5]),
        phi: Column::Each(&cols[6]),
        choice,
    }
}

fn read_inputs(rows: &[common::Row]) -> [Vec<f64>; 7] {
    ["R1", "R2", "G", "nu", "mu", "P", "phi"].map(|c| column(rows, c))
}

#[test]
fn reference_batch_against_vectors_scene() {
    let rows = read_rows("vectors_scene.csv");
    let cols = read_inputs(&rows);
    let mut out = Owned::new(rows.len());
    let bad = batch::estimate(
        &inputs(&cols, ModelChoice::Section9),
        &mut out.outputs(true),
        Model::Reference,
    )
    .unwrap();
    assert_eq!(bad, 0);
    let (mut main, mut rest) = (Worst::default(), Worst::default());
    for (i, row) in rows.iter().enumerate() {
        main.add("s", i, out.s[i], num(row, "s"));
        main.add("F", i, out.f[i], num(row, "F"));
        main.add("phi0", i, out.phi0[i], common::phi0(row));
        for name in [
            "theta", "kprime", "m", "n", "a", "b", "p0", "d", "Pstar", "P0star", "theta0",
        ] {
            let want = if name == "theta0" {
                common::theta0(row)
            } else {
                num(row, name)
            };
            rest.add(name, i, out.detail(name)[i], want);
        }
        assert!(out.detail("R")[i].is_nan(), "row {i}: R is line contact's");
        assert_eq!(regime(out.regime[i]), row["regime"], "row {i}");
        assert_eq!(out.model[i], 0, "row {i}: elliptic");
        assert_eq!(out.status[i], batch::OK, "row {i}");
    }
    main.assert_below(MAIN_BOUND);
    rest.assert_below(BOUND);
}

#[test]
fn reference_batch_against_vectors_line() {
    let rows = read_rows("vectors_line.csv");
    let cols = read_inputs(&rows);
    let mut out = Owned::new(rows.len());
    let bad = batch::estimate(
        &inputs(&cols, ModelChoice::Line),
        &mut out.outputs(true),
        Model::Reference,
    )
    .unwrap();
    assert_eq!(bad, 0);
    let (mut main, mut rest) = (Worst::default(), Worst::default());
    for (i, row) in rows.iter().enumerate() {
        main.add("s", i, out.s[i], num(row, "s"));
        main.add("F", i, out.f[i], num(row, "F"));
        main.add("phi0", i, out.phi0[i], common::phi0(row));
        for name in ["R", "b", "p0", "d", "Pstar", "P0star"] {
            rest.add(name, i, out.detail(name)[i], num(row, name));
        }
        assert_eq!(regime(out.regime[i]), row["regime"], "row {i}");
        assert_eq!(out.model[i], 1, "row {i}: line");
    }
    main.assert_below(MAIN_BOUND);
    rest.assert_below(BOUND);
}

/// Loads and angles over the demo scene's range, with a length so that section 9
/// switches to line contact at the low angles.
fn sweep() -> (Vec<f64>, Vec<f64>) {
    let mut load = Vec::new();
    let mut phi = Vec::new();
    for i in 0..40 {
        for j in 0..40 {
            load.push(10.0 * 1.25f64.powi(i));
            phi.push(if j % 2 == 0 { 1.0 } else { -1.0 } * 1e-6 * 1.3f64.powi(j));
        }
    }
    (load, phi)
}

/// The columns of `scene` repeated on every row, then the load and the angle.
fn scene_per_row(scene: &Scene, load: &[f64], phi: &[f64]) -> [Vec<f64>; 7] {
    let n = load.len();
    [
        vec![scene.r1(); n],
        vec![scene.r2(); n],
        vec![scene.shear_modulus(); n],
        vec![scene.poisson_ratio(); n],
        vec![scene.friction(); n],
        load.to_vec(),
        phi.to_vec(),
    ]
}

#[test]
fn cores_in_a_batch_answer_as_row_by_row() {
    let scene = Scene::DEMO.with_length(0.2).unwrap();
    let (load, phi) = sweep();
    let n = load.len();
    let one = Inputs::one_scene(&scene, Column::Each(&load), Column::Each(&phi));
    // The same scene given per row: prepared once per run of equal constants.
    let per_row_cols = scene_per_row(&scene, &load, &phi);
    let lengths = vec![0.2; n];
    let per_row = Inputs {
        length: Some(Column::Each(&lengths)),
        ..inputs(&per_row_cols, ModelChoice::Section9)
    };
    let f32_core = Auto::new(&scene).unwrap();
    let fixed_core = FixedAuto::new(&scene, 1e-2, 1e-10).unwrap();
    let fixed = Model::Fixed(Counts::Adc {
        load_lsb: 1e-2,
        angle_lsb: Some(1e-10),
    });
    let mut lines = 0;
    for inputs in [&one, &per_row] {
        let mut a = Owned::new(n);
        assert_eq!(
            batch::estimate(inputs, &mut a.outputs(true), Model::F32),
            Ok(0)
        );
        let mut b = Owned::new(n);
        assert_eq!(batch::estimate(inputs, &mut b.outputs(false), fixed), Ok(0));
        for i in 0..n {
            let e = f32_core.estimate(load[i] as f32, phi[i] as f32).unwrap();
            assert_eq!(a.s[i], f64::from(e.estimate.slip_ratio), "row {i}");
            assert_eq!(a.f[i], f64::from(e.estimate.axial_force), "row {i}");
            let phi0 = e.estimate.critical_angle.map_or(f64::NAN, f64::from);
            assert_eq!(a.phi0[i].to_bits(), phi0.to_bits(), "row {i}");
            assert_eq!(a.model[i], e.model as u8, "row {i}");
            lines += usize::from(a.model[i] == 1);
            let counts = (
                (load[i] / 1e-2).round() as u32,
                (phi[i] / 1e-10).round() as i32,
            );
            let x = fixed_core.estimate(counts.0, counts.1).unwrap().estimate;
            assert_eq!(b.s[i], x.slip_ratio.to_f64(), "row {i}");
            let force = x.axial_force.to_f64();
            let force = if x.axial_force_negative {
                -force
            } else {
                force
            };
            assert_eq!(b.f[i], force, "row {i}");
            assert_eq!(
                b.phi0[i].to_bits(),
                x.critical_angle.map_or(f64::NAN, |c| c.to_f64()).to_bits()
            );
        }
        // Every detail stays NaN for the cores: they do not compute them.
        assert!(a.details.iter().flatten().all(|x| x.is_nan()));
    }
    assert!(lines > 0, "the sweep reaches line contact");
}

/// One scene for all rows (the cores' block loops) answers every column as a scene
/// given per row (the row-by-row loop), bit for bit: on the hot path, off it (zero,
/// the asymptotics, line contact, phi0 beyond pi/2) and on refused rows, in full and
/// partial blocks, with and without a length, P and phi per row or one value.
#[test]
fn one_scene_answers_every_column_as_a_scene_per_row() {
    let (mut load, mut phi) = sweep();
    let edges = [
        (0.0, 2e-4),
        (1e3, 0.0),
        (1e3, -0.0),
        (-0.0, 2e-4),
        (f64::NAN, 2e-4),
        (1e3, f64::NAN),
        (-1.0, 2e-4),
        (f64::INFINITY, 2e-4),
        (1e3, 1.0),
        (1e3, 1.0f64.next_up()),
        (1e3, -1.5),
        (1e3, core::f64::consts::FRAC_PI_2),
        (1e3, core::f64::consts::FRAC_PI_2.next_up()),
        (1e3, 1e-40),
        (1e3, 1e-50),
        (1e-50, 2e-4),
        (1e-30, 2e-4),
        (1e39, 2e-4),
        (1e36, 2e-4),
        (1e3, 1e-12),
        (f64::MIN_POSITIVE, 1e-3),
    ];
    for (p, a) in edges {
        load.insert(37, p);
        phi.insert(37, a);
    }
    load.truncate(1000); // a partial block at the end
    phi.truncate(1000);
    let n = load.len();
    let fixed = Model::Fixed(Counts::Adc {
        load_lsb: 1e-2,
        angle_lsb: None,
    });
    for (scene, choice) in [
        (Scene::DEMO, ModelChoice::Section9),
        (Scene::DEMO.with_length(0.2).unwrap(), ModelChoice::Section9),
        (Scene::DEMO.with_length(0.2).unwrap(), ModelChoice::Line),
        (Scene::DEMO.with_length(0.2).unwrap(), ModelChoice::Elliptic),
        (
            Scene::new(0.05, 1.0, 79.3e9, 0.3, 0.3).unwrap(),
            ModelChoice::Section9,
        ),
    ] {
        let cols = scene_per_row(&scene, &load, &phi);
        let lengths = scene.length().map(|l| vec![l; n]);
        let per_row = Inputs {
            length: lengths.as_deref().map(Column::Each),
            ..inputs(&cols, choice)
        };
        let one = Inputs {
            choice,
            ..Inputs::one_scene(&scene, Column::Each(&load), Column::Each(&phi))
        };
        let scalars = Inputs {
            load: Column::One(load[40]),
            phi: Column::One(phi[40]),
            ..one
        };
        for model in [Model::F32, fixed] {
            let mut want = Owned::new(n);
            let mut got = Owned::new(n);
            let bad = batch::estimate(&per_row, &mut want.outputs(true), model).unwrap();
            assert_eq!(
                batch::estimate(&one, &mut got.outputs(true), model),
                Ok(bad)
            );
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            for (a, b) in [
                (&want.s, &got.s),
                (&want.f, &got.f),
                (&want.phi0, &got.phi0),
            ] {
                assert_eq!(bits(a), bits(b), "{model:?} {choice:?}");
            }
            assert_eq!(want.regime, got.regime, "{model:?} {choice:?}");
            assert_eq!(want.model, got.model, "{model:?} {choice:?}");
            assert_eq!(want.flags, got.flags, "{model:?} {choice:?}");
            assert_eq!(want.status, got.status, "{model:?} {choice:?}");
            assert!(got.details.iter().flatten().all(|x| x.is_nan()));
            let mut same = Owned::new(n);
            batch::estimate(&scalars, &mut same.outputs(false), model).unwrap();
            assert!(same.s.iter().all(|x| x.to_bits() == want.s[40].to_bits()));
            assert!(same.flags.iter().all(|x| *x == want.flags[40]));
        }
    }
}

#[test]
fn bad_rows_get_their_error_and_the_others_their_values() {
    let load = [1e3, f64::NAN, -1.0, 1e3, f64::INFINITY, 1e3, 1e3];
    let phi = [2e-4, 2e-4, 2e-4, f64::NAN, 2e-4, 2.0, 2e-4];
    let mu = [0.3, 0.3, 0.3, 0.3, 0.3, 0.3, -0.3];
    let inputs = Inputs {
        friction: Column::Each(&mu),
        ..Inputs::one_scene(&Scene::DEMO, Column::Each(&load), Column::Each(&phi))
    };
    let want = [
        None,
        Some(Error::Load),
        Some(Error::Load),
        Some(Error::Angle),
        Some(Error::Load),
        Some(Error::Angle),
        Some(Error::Friction),
    ];
    let fixed = Model::Fixed(Counts::Adc {
        load_lsb: 1e-2,
        angle_lsb: None,
    });
    for model in [Model::Reference, Model::F32, fixed] {
        let mut out = Owned::new(load.len());
        let bad = batch::estimate(&inputs, &mut out.outputs(true), model).unwrap();
        assert_eq!(bad, 6, "{model:?}");
        for (i, w) in want.iter().enumerate() {
            assert_eq!(batch::error_of(out.status[i]), *w, "{model:?} row {i}");
            if w.is_some() {
                assert!(out.s[i].is_nan() && out.f[i].is_nan() && out.phi0[i].is_nan());
                assert_eq!((out.regime[i], out.model[i]), (batch::NONE, batch::NONE));
            } else {
                assert!(out.s[i] > 0.0 && out.f[i] > 0.0 && out.phi0[i] > 0.0);
            }
        }
    }
}

#[test]
fn every_error_has_its_own_status() {
    let errors = [
        Error::Radius,
        Error::ShearModulus,
        Error::PoissonRatio,
        Error::Friction,
        Error::Length,
        Error::Load,
        Error::Angle,
        Error::PlaneHasNoEllipse,
        Error::Unsupported,
        Error::Force,
        Error::OutOfRange,
        Error::LengthTooShort,
    ];
    for e in errors {
        let code = batch::status_of(e);
        assert_ne!(code, batch::OK);
        assert_eq!(batch::error_of(code), Some(e));
    }
    assert_eq!(batch::error_of(batch::OK), None);
}

#[test]
fn columns_of_another_length_are_refused_before_any_row() {
    let load = [1e3; 3];
    let phi = [2e-4; 4];
    let inputs = Inputs::one_scene(&Scene::DEMO, Column::Each(&load), Column::Each(&phi));
    let mut out = Owned::new(3);
    assert_eq!(
        batch::estimate(&inputs, &mut out.outputs(false), Model::Reference),
        Err(Mismatch)
    );
    assert!(out.s.iter().all(|x| *x == 0.0), "nothing written");
    let mut short = Owned::new(4);
    short.f.pop();
    let inputs = Inputs::one_scene(&Scene::DEMO, Column::One(1e3), Column::Each(&phi));
    assert_eq!(
        batch::estimate(&inputs, &mut short.outputs(false), Model::F32),
        Err(Mismatch)
    );
    // Scalars only: the outputs' length.
    let inputs = Inputs::one_scene(&Scene::DEMO, Column::One(1e3), Column::One(2e-4));
    let mut out = Owned::new(2);
    assert_eq!(
        batch::estimate(&inputs, &mut out.outputs(false), Model::Reference),
        Ok(0)
    );
    assert_eq!(out.s[0], out.s[1]);
}

#[cfg(feature = "rayon")]
#[test]
fn threads_give_the_same_numbers() {
    let (load, phi) = sweep();
    let load: Vec<f64> = load.iter().cycle().take(50_000).copied().collect();
    let phi: Vec<f64> = phi.iter().cycle().take(50_000).copied().collect();
    let scene = Scene::DEMO.with_length(0.2).unwrap();
    let inputs = Inputs::one_scene(&scene, Column::Each(&load), Column::Each(&phi));
    for model in [Model::Reference, Model::F32] {
        let (mut a, mut b) = (Owned::new(load.len()), Owned::new(load.len()));
        batch::estimate(&inputs, &mut a.outputs(true), model).unwrap();
        batch::par_estimate(&inputs, &mut b.outputs(true), model).unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.s), bits(&b.s));
        assert_eq!(bits(&a.f), bits(&b.f));
        assert_eq!(bits(&a.phi0), bits(&b.phi0));
        assert_eq!(bits(&a.details[5]), bits(&b.details[5]));
    }
}

/// Every model of a batch takes f64 inputs and draws the right angle where the
/// reference does: f64's FRAC_PI_2 (below the true pi/2) is answered, the f64 above it
/// refused, also by the f32 core, whose rounding would carry it onto f32's FRAC_PI_2.
#[test]
fn every_model_of_a_batch_draws_the_right_angle_at_f64s() {
    let scene = Scene::DEMO;
    let half_pi = core::f64::consts::FRAC_PI_2;
    let phi = [half_pi, half_pi.next_up(), -half_pi, -half_pi.next_up()];
    let load = [1e3; 4];
    let inputs = Inputs::one_scene(&scene, Column::Each(&load), Column::Each(&phi));
    let angle = batch::status_of(Error::Angle);
    let fixed = Model::Fixed(Counts::Adc {
        load_lsb: 1e-2,
        angle_lsb: Some(1e-6),
    });
    for model in [Model::Reference, Model::F32, fixed] {
        let mut out = Owned::new(phi.len());
        assert_eq!(
            batch::estimate(&inputs, &mut out.outputs(false), model),
            Ok(2),
            "{model:?}"
        );
        assert_eq!(out.status, [0, angle, 0, angle], "{model:?}");
    }
}

/// The batch without details (the reference's fast path) against the batch with them
/// (the reference itself): a scene per row over the 50-digit scenes, and one scene with
/// a length over the benchmark's loads (section 9 switching to line contact at small
/// angles).
#[test]
fn reference_without_details_is_the_reference() {
    let rows = read_rows("vectors_scene.csv");
    let cols = read_inputs(&rows);
    let (mut load, mut phi) = (Vec::new(), Vec::new());
    for i in 0..20_000 {
        load.push(200.0 * 100f64.powf((i % 97) as f64 / 96.0));
        phi.push(1e-6 * 1e5f64.powf((i % 89) as f64 / 88.0) * if i % 2 == 0 { 1.0 } else { -1.0 });
    }
    let scene = Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3)
        .unwrap()
        .with_length(0.2)
        .unwrap();
    let cases = [
        inputs(&cols, ModelChoice::Section9),
        Inputs::one_scene(&scene, Column::Each(&load), Column::Each(&phi)),
    ];
    for (case, inputs) in cases.iter().enumerate() {
        let n = if case == 0 { rows.len() } else { load.len() };
        let (mut fast, mut slow) = (Owned::new(n), Owned::new(n));
        batch::estimate(inputs, &mut fast.outputs(false), Model::Reference).unwrap();
        batch::estimate(inputs, &mut slow.outputs(true), Model::Reference).unwrap();
        let mut worst = Worst::default();
        for i in 0..n {
            worst.add("s", i, fast.s[i], slow.s[i]);
            worst.add("F", i, fast.f[i], slow.f[i]);
            worst.add("phi0", i, fast.phi0[i], slow.phi0[i]);
        }
        // Both within a few ulps of the exact values.
        worst.assert_below(3e-15);
        assert_eq!(fast.regime, slow.regime);
        assert_eq!(fast.model, slow.model);
        assert_eq!(fast.flags, slow.flags);
        assert_eq!(fast.status, slow.status);
        if case == 1 {
            assert!(slow.model.contains(&0) && slow.model.contains(&1));
        }
    }
}

/// The largest relative error of d/b, F and phi0 of `model` against the reference over
/// the rows.
fn worst_against_reference(model: Model, load: &[f64], phi: &[f64]) -> f64 {
    let inputs = Inputs::one_scene(&Scene::DEMO, Column::Each(load), Column::Each(phi));
    let mut want = Owned::new(load.len());
    let mut got = Owned::new(load.len());
    batch::estimate(&inputs, &mut want.outputs(false), Model::Reference).unwrap();
    assert_eq!(
        batch::estimate(&inputs, &mut got.outputs(false), model),
        Ok(0)
    );
    let rel = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| if x == y { 0.0 } else { (x / y - 1.0).abs() })
            .fold(0.0, f64::max)
    };
    rel(&got.s, &want.s)
        .max(rel(&got.f, &want.f))
        .max(rel(&got.phi0, &want.phi0))
}

#[test]
fn exact_counts_carry_the_cores_error_and_an_adc_its_rounding() {
    // Small loads and angles, where an ADC's 10 mN and finest angle are few counts
    // (0.104 N rounds to 10 counts, 4 % less).
    let load = [0.104, 0.1049, 0.376, 1.004, 25.3, 2e3, 1.7e4];
    let phi = [1.1e-7, 3.3e-4, 2.2e-7, 1.1e-7, 5e-5, 2e-4, -7e-4];
    let exact = worst_against_reference(Model::Fixed(Counts::Exact), &load, &phi);
    assert!(exact < 1e-5, "exact counts: {exact:e}");
    let adc = Model::Fixed(Counts::Adc {
        load_lsb: 1e-2,
        angle_lsb: None,
    });
    let rounded = worst_against_reference(adc, &load, &phi);
    assert!(
        rounded > 1e-2,
        "an ADC's rounding at 10 counts: {rounded:e}"
    );
}

#[test]
fn an_adc_lsb_the_core_cannot_take_is_named() {
    let scene = Scene::DEMO;
    let refused = |load: f64, angle: Option<f64>| {
        batch::adc_lsb_refused(&scene, ModelChoice::Section9, load, angle)
    };
    assert_eq!(refused(1e-2, None), None);
    assert_eq!(refused(1e-2, Some(1e-8)), None);
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e-300, 1e300] {
        assert_eq!(refused(bad, None), Some(batch::RefusedLsb::Load), "{bad:e}");
        assert_eq!(
            refused(1e-2, Some(bad)),
            Some(batch::RefusedLsb::Angle),
            "{bad:e}"
        );
    }
    // Finer than the tables allow: one count below theta = 2^-40 rad.
    assert_eq!(refused(1e-2, Some(1e-14)), Some(batch::RefusedLsb::Angle));
    // A scene refused whatever the LSBs: not the LSBs' fault.
    let plane = Scene::new(0.05, f64::INFINITY, 79.3e9, 0.3, 0.3).unwrap();
    assert_eq!(
        batch::adc_lsb_refused(&plane, ModelChoice::Elliptic, 1e-2, None),
        None
    );
}

/// The AVX2 build of the batch answers every column as the baseline build, bit for bit:
/// one scene for all (the reference's lanes, the f32 core's blocks) and a scene per row
/// (the 50-digit file's scenes, and scenes varied row by row over the sweep), every
/// model, without and with details.
#[cfg(target_arch = "x86_64")]
#[test]
fn avx2_build_gives_the_same_bits() {
    if !std::arch::is_x86_feature_detected!("avx2") {
        eprintln!("no AVX2 on this CPU: nothing to compare");
        return;
    }
    let (load, phi) = sweep();
    let n = load.len();
    // Scenes varied row by row: radii, modulus and friction over their practical ranges.
    let vary = |i: usize, lo: f64, hi: f64, k: usize| lo + (hi - lo) * ((i * k) % 97) as f64 / 96.0;
    let varied: [Vec<f64>; 7] = [
        (0..n).map(|i| vary(i, 0.01, 0.1, 7)).collect(),
        (0..n).map(|i| vary(i, 0.01, 0.1, 13)).collect(),
        (0..n).map(|i| vary(i, 70e9, 85e9, 29)).collect(),
        vec![0.3; n],
        (0..n).map(|i| vary(i, 0.05, 0.6, 41)).collect(),
        load.clone(),
        phi.clone(),
    ];
    let file = read_inputs(&read_rows("vectors_scene.csv"));
    let scene = Scene::DEMO;
    let one = Inputs::one_scene(&scene, Column::Each(&load), Column::Each(&phi));
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    for input in [
        one,
        inputs(&varied, ModelChoice::Section9),
        inputs(&file, ModelChoice::Section9),
    ] {
        let rows = match input.load {
            Column::Each(x) => x.len(),
            Column::One(_) => 1,
        };
        for model in [Model::Reference, Model::F32, Model::Fixed(Counts::Exact)] {
            for details in [false, true] {
                let (mut a, mut b) = (Owned::new(rows), Owned::new(rows));
                let bad_a = batch::estimate(&input, &mut a.outputs(details), model).unwrap();
                // SAFETY: the CPU has AVX2 (checked above), the only feature it needs.
                let bad_b = unsafe { batch::estimate_avx2(&input, &mut b.outputs(details), model) }
                    .unwrap();
                assert_eq!(bad_a, bad_b);
                assert_eq!(bits(&a.s), bits(&b.s), "{model:?}");
                assert_eq!(bits(&a.f), bits(&b.f), "{model:?}");
                assert_eq!(bits(&a.phi0), bits(&b.phi0), "{model:?}");
                assert_eq!((&a.regime, &a.model), (&b.regime, &b.model));
                assert_eq!((&a.flags, &a.status), (&b.flags, &b.status));
                for (x, y) in a.details.iter().zip(&b.details) {
                    assert_eq!(bits(x), bits(y));
                }
            }
        }
    }
}
