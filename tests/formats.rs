//! docs/formats.md against the code: the lengths, kinds, versions and offsets it
//! states are those the crate writes, and its worked example is the crate's bytes.

use misalign::Scene;
use misalign::fixed::{FixedAuto, FixedEllipticScene, FixedLineScene};
use misalign::float::{Auto, EllipticScene, LineScene};

fn spec() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/formats.md")).unwrap()
}

fn demo() -> Scene {
    Scene::new(0.05, 0.05, 79.3e9, 0.3, 0.3).unwrap()
}

/// The demo rollers 0.3 m long: both models present in an `Auto` scene.
fn rollers() -> Scene {
    demo().with_length(0.3).unwrap()
}

const LOAD_LSB: f64 = 1e-3;
const ANGLE_LSB: f64 = 1e-11;

fn f32_at(bytes: &[u8], at: usize) -> f32 {
    f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
}

/// Every prepared scene's frame: magic, kind, version 1, the CRC-32 of the rest last,
/// and its kind and length in the page's table.
#[test]
fn prepared_frames_and_lengths_are_the_documented_ones() {
    let spec = spec();
    let scenes: [(&str, Vec<u8>); 6] = [
        (
            "fixed::FixedEllipticScene",
            FixedEllipticScene::new(&demo(), LOAD_LSB, ANGLE_LSB)
                .unwrap()
                .to_bytes()
                .to_vec(),
        ),
        (
            "fixed::FixedLineScene",
            FixedLineScene::new(&rollers(), LOAD_LSB, ANGLE_LSB)
                .unwrap()
                .to_bytes()
                .to_vec(),
        ),
        (
            "fixed::FixedAuto",
            FixedAuto::new(&rollers(), LOAD_LSB, ANGLE_LSB)
                .unwrap()
                .to_bytes()
                .to_vec(),
        ),
        (
            "float::EllipticScene",
            EllipticScene::new(&demo()).unwrap().to_bytes().to_vec(),
        ),
        (
            "float::LineScene",
            LineScene::new(&rollers()).unwrap().to_bytes().to_vec(),
        ),
        (
            "float::Auto",
            Auto::new(&rollers()).unwrap().to_bytes().to_vec(),
        ),
    ];
    for (i, (name, bytes)) in scenes.iter().enumerate() {
        let n = bytes.len();
        assert_eq!(&bytes[..2], b"MS", "{name}");
        assert_eq!(usize::from(bytes[2]), i + 1, "{name}: kind");
        assert_eq!(bytes[3], misalign::prepared::FORMAT_VERSION, "{name}");
        assert_eq!(bytes[3], 1, "{name}: the page documents version 1");
        let crc = misalign::prepared::crc32(&bytes[..n - 4]);
        assert_eq!(bytes[n - 4..], crc.to_le_bytes(), "{name}: CRC-32 last");
        let row = format!("| {} | `{name}` | {n} |", i + 1);
        assert!(spec.contains(&row), "docs/formats.md lacks {row}");
    }
    // The CRC is zlib's: its check value.
    assert_eq!(misalign::prepared::crc32(b"123456789"), 0xCBF4_3926);
    assert!(spec.contains("0xCBF43926"));
}

/// The worked example: the demo rollers for the f32 elliptic core, byte for byte, and
/// the fields at their documented offsets.
#[test]
fn the_worked_example_is_the_crates_bytes() {
    let bytes = EllipticScene::new(&demo()).unwrap().to_bytes();
    let hex: String = bytes.iter().map(|b| format!("{b:02x}")).collect();
    let spec = spec();
    let documented: String = spec
        .lines()
        .find(|l| l.starts_with("4d53 04"))
        .expect("the example's hex line")
        .split_whitespace()
        .collect();
    assert_eq!(documented, hex);
    assert_eq!(f32_at(&bytes, 4), 1.0, "c of equal radii");
    assert_eq!(f32_at(&bytes, 20), 0.3, "mu");
    assert_eq!(f32_at(&bytes, 28), 0.8, "the default risk threshold");
}

/// `Auto` and `FixedAuto` nest their models' constants at the documented offsets.
#[test]
fn auto_scenes_nest_their_models_where_documented() {
    let scene = rollers();
    let auto = Auto::new(&scene).unwrap().to_bytes();
    let ellipse = EllipticScene::new(&scene).unwrap().to_bytes();
    let line = LineScene::new(&scene).unwrap().to_bytes();
    assert_eq!(auto.len(), 83);
    assert_eq!(auto[4], 1);
    assert_eq!(auto[5..37], ellipse[4..36]);
    assert_eq!(auto[37], 1);
    assert_eq!(auto[38..70], line[4..36]);
    assert_eq!(f32_at(&auto, 70), (2.0 / 0.3) as f32);
    assert_eq!(auto[74], 0, "section 9 per sample");
    assert_eq!(f32_at(&auto, 75), 0.8);

    let fixed = FixedAuto::new(&scene, LOAD_LSB, ANGLE_LSB)
        .unwrap()
        .to_bytes();
    let ellipse = FixedEllipticScene::new(&scene, LOAD_LSB, ANGLE_LSB)
        .unwrap()
        .to_bytes();
    let line = FixedLineScene::new(&scene, LOAD_LSB, ANGLE_LSB)
        .unwrap()
        .to_bytes();
    assert_eq!(fixed.len(), 124);
    assert_eq!(fixed[4], 1);
    assert_eq!(fixed[5..53], ellipse[4..52]);
    assert_eq!(fixed[53], 1);
    assert_eq!(fixed[54..98], line[4..48]);
    assert_eq!(fixed[98], 1, "a length");
    assert_eq!(fixed[107], 0, "section 9 per sample");
    assert_eq!(f32_at(&fixed, 112), LOAD_LSB as f32);
    assert_eq!(f32_at(&fixed, 116), ANGLE_LSB as f32);
    // The fixed-point scenes end in their LSBs too.
    assert_eq!(f32_at(&ellipse, 44), LOAD_LSB as f32);
    assert_eq!(f32_at(&ellipse, 48), ANGLE_LSB as f32);
    assert_eq!(f32_at(&line, 40), LOAD_LSB as f32);
    assert_eq!(f32_at(&line, 44), ANGLE_LSB as f32);
}

#[cfg(feature = "sequential-storage")]
mod records {
    use super::{f32_at, spec};
    use misalign::monitor::{Config, MonitorState, Thresholds};
    use misalign::storage::{Checkpoint, codec, kind};

    fn record<T: Checkpoint>(value: &T, sequence: u32) -> Vec<u8> {
        let mut out = vec![0; codec::record_len(T::SIZE)];
        let n = codec::encode(value, sequence, &mut out).unwrap();
        assert_eq!(n, out.len());
        out
    }

    /// The frame around a payload: magic, kind, framing, version, length, reserved,
    /// sequence, payload, CRC-32.
    fn check_frame<T: Checkpoint>(bytes: &[u8], sequence: u32) {
        assert_eq!(&bytes[..4], b"MSLG");
        assert_eq!(bytes[4], T::KIND);
        assert_eq!(bytes[5], codec::FRAMING);
        assert_eq!(bytes[5], 1, "the page documents framing 1");
        assert_eq!(u16::from_le_bytes([bytes[6], bytes[7]]), T::VERSION);
        assert_eq!(
            usize::from(u16::from_le_bytes([bytes[8], bytes[9]])),
            T::SIZE
        );
        assert_eq!(bytes[10..12], [0, 0]);
        assert_eq!(bytes[12..16], sequence.to_le_bytes());
        let n = bytes.len();
        assert_eq!(n, 16 + T::SIZE + 4);
        assert_eq!(
            bytes[n - 4..],
            misalign::prepared::crc32(&bytes[..n - 4]).to_le_bytes()
        );
    }

    fn documented_row<T: Checkpoint>(kind_name: &str, type_name: &str) {
        let row = format!(
            "| {} (`storage::kind::{kind_name}`) | `{type_name}` | {} | {} |",
            T::KIND,
            T::VERSION,
            T::SIZE
        );
        assert!(spec().contains(&row), "docs/formats.md lacks {row}");
    }

    #[test]
    fn the_monitor_state_record_is_the_documented_one() {
        documented_row::<MonitorState>("MONITOR_STATE", "monitor::MonitorState");
        assert_eq!(MonitorState::KIND, kind::MONITOR_STATE);
        let bytes = record(&MonitorState::default(), 7);
        check_frame::<MonitorState>(&bytes, 7);
        let payload = &bytes[16..bytes.len() - 4];
        assert_eq!(payload[13], 0, "a fresh monitor is Stopped (state code 0)");
        assert_eq!(payload[95], 1, "a fresh monitor is armed for Approaching");
        assert_eq!(payload[791], 0, "no event held: the last byte, the length");
    }

    #[test]
    fn the_configuration_record_is_the_documented_one() {
        documented_row::<Config>("MONITOR_CONFIG", "monitor::Config");
        let config = Config::default();
        let bytes = record(&config, 1);
        check_frame::<Config>(&bytes, 1);
        let p = &bytes[16..bytes.len() - 4];
        let Thresholds::SlipRatio {
            warning,
            alarm,
            deadband,
        } = config.thresholds
        else {
            panic!("the default thresholds are on d/b");
        };
        assert_eq!(p[0], 0, "thresholds on d/b");
        assert_eq!(
            [f32_at(p, 1), f32_at(p, 5), f32_at(p, 9)],
            [warning, alarm, deadband]
        );
        assert_eq!(p[13..17], config.on_delay_ms.to_le_bytes());
        assert_eq!(p[25..29], config.inhibit_ms.to_le_bytes());
        assert_eq!(f32_at(p, 29), config.stop_load);
        assert_eq!(f32_at(p, 57), config.force_max);
        assert_eq!(p[61], u8::from(config.spikes.is_some()));
        assert_eq!(f32_at(p, 75), config.smoothing_tau_s);
        assert_eq!(p[79..83], config.stuck_ms.to_le_bytes());
        assert_eq!(p[87], u8::from(config.trend.is_some()));
        assert_eq!(p[97], u8::from(config.friction.is_some()));
    }

    #[cfg(feature = "sensors")]
    #[test]
    fn the_calibration_record_is_documented() {
        use misalign::storage::SensorCalibration;
        documented_row::<SensorCalibration>("CALIBRATION", "storage::SensorCalibration");
    }
}
