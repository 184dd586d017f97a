//! Prepared scenes as bytes (`misalign::prepared`): a scene loaded from the bytes of a
//! prepared one answers bit for bit as the prepared one, over many scenes and samples,
//! in both cores and every scene type; damaged or foreign bytes are refused with a
//! typed error, never a panic.

use misalign::fixed::{FixedAuto, FixedEllipticScene, FixedLineScene};
use misalign::float::{Auto, EllipticScene, LineScene};
use misalign::prepared::{FORMAT_VERSION, PreparedError, crc32};
use misalign::reference::ModelChoice;
use misalign::{Estimate, Scene};

/// A small deterministic generator (xorshift64*), so that the scenes are the same on
/// every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Log-uniform in [lo, hi].
    fn log(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + self.unit() * (hi.ln() - lo.ln())).exp()
    }
}

/// Many installations: radii from 1 mm to 1 m (a plane now and then), steel to
/// rubber-like moduli, every Poisson ratio, mu from 0.02 to 2, with and without a length.
fn scenes(n: usize) -> Vec<Scene> {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut out = vec![Scene::DEMO, Scene::DEMO.with_length(0.3).unwrap()];
    while out.len() < n {
        let r1 = rng.log(1e-3, 1.0);
        let r2 = if rng.unit() < 0.1 {
            f64::INFINITY
        } else {
            rng.log(1e-3, 1.0)
        };
        let g = rng.log(1e6, 3e11);
        let nu = 0.5 * rng.unit();
        let mu = rng.log(0.02, 2.0);
        let Ok(scene) = Scene::new(r1, r2, g, nu, mu) else {
            continue;
        };
        let scene = if rng.unit() < 0.5 {
            scene.with_length(rng.log(1e-3, 2.0)).unwrap()
        } else {
            scene
        };
        out.push(scene);
    }
    out
}

/// Samples in SI: loads from 1 mN to 1 MN and 0, angles from 1e-9 to 0.5 rad of both
/// signs and 0, and a few the scenes refuse.
fn samples() -> Vec<(f32, f32)> {
    let mut rng = Rng(7);
    let mut out = vec![
        (0.0, 0.0),
        (0.0, 1e-4),
        (1e3, 0.0),
        (1e3, 2e-4),
        (-1.0, 1e-4),
    ];
    out.push((1e3, 2.0));
    out.push((f32::NAN, 1e-4));
    for _ in 0..60 {
        let load = rng.log(1e-3, 1e6) as f32;
        let phi = rng.log(1e-9, 0.5) as f32;
        out.push((load, if rng.unit() < 0.5 { -phi } else { phi }));
    }
    out
}

/// The fixed-point LSBs: the firmware's (1 mN, 10 prad) and coarser ones.
const LSBS: [(f64, f64); 3] = [(1e-3, 1e-11), (1e-2, 1e-9), (1.0, 1e-7)];

/// Counts for a fixed-point scene: the SI samples at its LSBs, where they fit.
fn counts(samples: &[(f32, f32)], lsb: (f64, f64)) -> Vec<(u32, i32)> {
    let mut out = vec![(0, 0), (1, 1), (u32::MAX, i32::MAX), (u32::MAX, i32::MIN)];
    for &(load, phi) in samples {
        let (l, a) = (load as f64 / lsb.0, phi as f64 / lsb.1);
        if (0.0..4e9).contains(&l) && a.abs() < 2e9 {
            out.push((l as u32, a as i32));
        }
    }
    out
}

/// Every field of an f32 answer, by its bits (NaN and -0 included).
fn bits(e: &Estimate) -> impl PartialEq + std::fmt::Debug + use<> {
    (
        e.slip_ratio.to_bits(),
        e.regime,
        e.axial_force.to_bits(),
        e.critical_angle.map(f32::to_bits),
        e.margin.map(f32::to_bits),
        e.microslip_risk,
    )
}

/// `loaded` is `prepared`, field for field (`Debug` prints every field, an f32 by its
/// shortest round-trip form), and writes the same bytes.
fn same<T: std::fmt::Debug>(prepared: &T, loaded: &T) {
    assert_eq!(format!("{prepared:?}"), format!("{loaded:?}"));
}

#[test]
fn f32_scenes_from_bytes_answer_bit_for_bit() {
    let samples = samples();
    let (mut elliptic, mut line, mut auto) = (0, 0, 0);
    for scene in scenes(400) {
        if let Ok(prepared) = EllipticScene::new(&scene) {
            let loaded = EllipticScene::from_bytes(&prepared.to_bytes()).unwrap();
            same(&prepared, &loaded);
            assert_eq!(loaded.to_bytes(), prepared.to_bytes());
            for &(p, phi) in &samples {
                let (a, b) = (prepared.estimate(p, phi), loaded.estimate(p, phi));
                assert_eq!(
                    a.map(|e| bits(&e)),
                    b.map(|e| bits(&e)),
                    "{scene:?} {p} {phi}"
                );
                let (a, b) = (prepared.details(p, phi), loaded.details(p, phi));
                assert_eq!(format!("{a:?}"), format!("{b:?}"));
            }
            elliptic += 1;
        }
        if let Ok(prepared) = LineScene::new(&scene) {
            let loaded = LineScene::from_bytes(&prepared.to_bytes()).unwrap();
            same(&prepared, &loaded);
            for &(p, phi) in &samples {
                let (a, b) = (prepared.estimate(p, phi), loaded.estimate(p, phi));
                assert_eq!(
                    a.map(|e| bits(&e)),
                    b.map(|e| bits(&e)),
                    "{scene:?} {p} {phi}"
                );
            }
            line += 1;
        }
        for choice in [
            ModelChoice::Section9,
            ModelChoice::Elliptic,
            ModelChoice::Line,
        ] {
            let Ok(prepared) = Auto::with_choice(&scene, choice) else {
                continue;
            };
            let prepared = prepared.with_risk_slip_ratio(0.6).unwrap();
            let loaded = Auto::from_bytes(&prepared.to_bytes()).unwrap();
            same(&prepared, &loaded);
            for &(p, phi) in &samples {
                let (a, b) = (prepared.estimate(p, phi), loaded.estimate(p, phi));
                let key = |e: misalign::float::AutoEstimate| {
                    (e.model, e.near_model_switch, bits(&e.estimate))
                };
                assert_eq!(a.map(key), b.map(key), "{scene:?} {p} {phi}");
            }
            auto += 1;
        }
    }
    assert!(
        elliptic > 300 && line > 300 && auto > 900,
        "{elliptic} {line} {auto}"
    );
}

#[test]
fn fixed_scenes_from_bytes_answer_bit_for_bit() {
    let samples = samples();
    let (mut elliptic, mut line, mut auto) = (0, 0, 0);
    for scene in scenes(300) {
        for lsb in LSBS {
            let counts = counts(&samples, lsb);
            if let Ok(prepared) = FixedEllipticScene::new(&scene, lsb.0, lsb.1) {
                let loaded = FixedEllipticScene::from_bytes(&prepared.to_bytes()).unwrap();
                same(&prepared, &loaded);
                assert_eq!(loaded.to_bytes(), prepared.to_bytes());
                for &(p, a) in &counts {
                    assert_eq!(prepared.estimate(p, a), loaded.estimate(p, a));
                    assert_eq!(prepared.details(p, a), loaded.details(p, a));
                }
                elliptic += 1;
            }
            if let Ok(prepared) = FixedLineScene::new(&scene, lsb.0, lsb.1) {
                let loaded = FixedLineScene::from_bytes(&prepared.to_bytes()).unwrap();
                same(&prepared, &loaded);
                for &(p, a) in &counts {
                    assert_eq!(prepared.estimate(p, a), loaded.estimate(p, a));
                }
                line += 1;
            }
            for choice in [
                ModelChoice::Section9,
                ModelChoice::Elliptic,
                ModelChoice::Line,
            ] {
                let Ok(prepared) = FixedAuto::with_choice(&scene, lsb.0, lsb.1, choice) else {
                    continue;
                };
                let loaded = FixedAuto::from_bytes(&prepared.to_bytes()).unwrap();
                same(&prepared, &loaded);
                for &(p, a) in &counts {
                    assert_eq!(prepared.estimate(p, a), loaded.estimate(p, a));
                }
                for &(p, phi) in &samples {
                    use misalign::Estimator;
                    let (a, b) = (prepared.estimate_si(p, phi), loaded.estimate_si(p, phi));
                    assert_eq!(a.map(|e| bits(&e)), b.map(|e| bits(&e)));
                }
                auto += 1;
            }
        }
    }
    assert!(
        elliptic > 400 && line > 400 && auto > 1200,
        "{elliptic} {line} {auto}"
    );
}

/// Every scene type's bytes of the demo scene (with a length, for both models).
fn demo_bytes() -> Vec<(&'static str, Vec<u8>)> {
    let s = Scene::DEMO.with_length(0.3).unwrap();
    vec![
        (
            "fixed elliptic",
            FixedEllipticScene::new(&s, 1e-3, 1e-11)
                .unwrap()
                .to_bytes()
                .to_vec(),
        ),
        (
            "fixed line",
            FixedLineScene::new(&s, 1e-3, 1e-11)
                .unwrap()
                .to_bytes()
                .to_vec(),
        ),
        (
            "fixed auto",
            FixedAuto::new(&s, 1e-3, 1e-11).unwrap().to_bytes().to_vec(),
        ),
        (
            "f32 elliptic",
            EllipticScene::new(&s).unwrap().to_bytes().to_vec(),
        ),
        ("f32 line", LineScene::new(&s).unwrap().to_bytes().to_vec()),
        ("f32 auto", Auto::new(&s).unwrap().to_bytes().to_vec()),
    ]
}

/// Loads `bytes` as the type named `kind`: `Ok(())` or the error.
fn load(kind: &str, bytes: &[u8]) -> Result<(), PreparedError> {
    match kind {
        "fixed elliptic" => FixedEllipticScene::from_bytes(bytes).map(drop),
        "fixed line" => FixedLineScene::from_bytes(bytes).map(drop),
        "fixed auto" => FixedAuto::from_bytes(bytes).map(drop),
        "f32 elliptic" => EllipticScene::from_bytes(bytes).map(drop),
        "f32 line" => LineScene::from_bytes(bytes).map(drop),
        "f32 auto" => Auto::from_bytes(bytes).map(drop),
        _ => unreachable!(),
    }
}

#[test]
fn the_format_is_as_documented() {
    for (kind, bytes) in demo_bytes() {
        assert_eq!(&bytes[..2], b"MS", "{kind}");
        assert_eq!(bytes[3], FORMAT_VERSION, "{kind}");
        let n = bytes.len();
        assert_eq!(
            crc32(&bytes[..n - 4]).to_le_bytes(),
            bytes[n - 4..],
            "{kind}"
        );
        assert_eq!(load(kind, &bytes), Ok(()), "{kind}");
    }
    // zlib's check value.
    assert_eq!(crc32(b"123456789"), 0xcbf4_3926);
}

#[test]
fn damaged_bytes_are_refused() {
    for (kind, bytes) in demo_bytes() {
        // Every byte changed to every other value: the CRC-32 catches each (or the
        // header check before it).
        for i in 0..bytes.len() {
            for v in 0..=255u8 {
                if v == bytes[i] {
                    continue;
                }
                let mut b = bytes.clone();
                b[i] = v;
                assert!(load(kind, &b).is_err(), "{kind}: byte {i} = {v} accepted");
            }
        }
        // Too short, too long, empty.
        for n in 0..bytes.len() {
            assert_eq!(
                load(kind, &bytes[..n]),
                Err(PreparedError::Length),
                "{kind}"
            );
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert_eq!(load(kind, &longer), Err(PreparedError::Length), "{kind}");
        // Another version, with its checksum made right: refused by the version.
        let mut b = bytes.clone();
        b[3] = FORMAT_VERSION + 1;
        reseal(&mut b);
        assert_eq!(load(kind, &b), Err(PreparedError::Version), "{kind}");
        let mut b = bytes.clone();
        b[0] = b'X';
        reseal(&mut b);
        assert_eq!(load(kind, &b), Err(PreparedError::Magic), "{kind}");
    }
    // Another type's bytes.
    let all = demo_bytes();
    for (kind, _) in &all {
        for (other, bytes) in &all {
            if kind != other {
                assert!(load(kind, bytes).is_err(), "{kind} loaded {other}'s bytes");
            }
        }
    }
}

/// Rewrites the CRC-32 of `b` for its content.
fn reseal(b: &mut [u8]) {
    let n = b.len() - 4;
    let crc = crc32(&b[..n]);
    b[n..].copy_from_slice(&crc.to_le_bytes());
}

/// Bytes with a valid checksum but constants no preparation makes (a tool with a bug,
/// or forged): each 32-bit field set to extreme values and resealed is refused as
/// `Value`, or, where the value is one a scene may have, loads and answers every
/// sample without a panic.
#[test]
fn resealed_extreme_values_are_refused_or_answer() {
    let extremes = [
        0u32,
        1,
        0x7f7f_ffff,
        0x7f80_0000,
        0x7fc0_0000,
        0x8000_0000,
        0xff80_0000,
        0x6400_0000,
        0x9c00_0000,
        u32::MAX,
    ];
    let samples = samples();
    for (kind, bytes) in demo_bytes() {
        let n = bytes.len();
        for at in 4..n - 4 {
            for x in extremes {
                let mut b = bytes.clone();
                let end = (at + 4).min(n - 4);
                b[at..end].copy_from_slice(&x.to_le_bytes()[..end - at]);
                reseal(&mut b);
                match load(kind, &b) {
                    Ok(()) => answer_all(kind, &b, &samples),
                    Err(e) => assert_eq!(e, PreparedError::Value, "{kind} at {at}"),
                }
            }
        }
    }
}

/// Every sample through a scene loaded from `bytes`: no panic (the answers may be
/// errors).
fn answer_all(kind: &str, bytes: &[u8], samples: &[(f32, f32)]) {
    use misalign::Estimator;
    fn run<E: Estimator>(core: E, samples: &[(f32, f32)]) {
        for &(p, phi) in samples {
            let _ = core.estimate_si(p, phi);
        }
    }
    match kind {
        "fixed elliptic" => run(FixedEllipticScene::from_bytes(bytes).unwrap(), samples),
        "fixed line" => run(FixedLineScene::from_bytes(bytes).unwrap(), samples),
        "fixed auto" => run(FixedAuto::from_bytes(bytes).unwrap(), samples),
        "f32 elliptic" => run(EllipticScene::from_bytes(bytes).unwrap(), samples),
        "f32 line" => run(LineScene::from_bytes(bytes).unwrap(), samples),
        "f32 auto" => run(Auto::from_bytes(bytes).unwrap(), samples),
        _ => unreachable!(),
    }
}
