//! The sensors' calibration ([`SensorCalibration`], the node's sensors' whole
//! calibration) as one stored record under [`kind::CALIBRATION`] (features
//! `sequential-storage` and `sensors`): the load cell on its HX711, the two
//! misalignment probes, the tachometer. A record is put back only if every part passes
//! its own `validate`.

use super::{Checkpoint, CodecError, Reader, Writer, kind};
use crate::sensors::{
    Hx711Channel, LoadCalibration, MisalignmentCalibration, ProbeCalibration, ProbeSpec,
    SensorCalibration, SpeedCalibration,
};

const LOAD_SIZE: usize = 1 + 4 * 4;
const PROBE_SIZE: usize = 2 * 4 + 3 * 4;
const MISALIGNMENT_SIZE: usize = 2 * PROBE_SIZE + 2 * 4;
const SPEED_SIZE: usize = 1 + 3 * 4;

fn channel_code(c: Hx711Channel) -> u8 {
    match c {
        Hx711Channel::A128 => 0,
        Hx711Channel::A64 => 1,
        Hx711Channel::B32 => 2,
    }
}

fn channel(code: u8) -> Result<Hx711Channel, CodecError> {
    match code {
        0 => Ok(Hx711Channel::A128),
        1 => Ok(Hx711Channel::A64),
        2 => Ok(Hx711Channel::B32),
        _ => Err(CodecError::InvalidValue),
    }
}

fn put_probe(w: &mut Writer<'_>, p: &ProbeCalibration) -> Result<(), CodecError> {
    w.f32(p.zero_counts)?;
    w.f32(p.metres_per_count)?;
    w.f32(p.spec.min_m)?;
    w.f32(p.spec.max_m)?;
    w.f32(p.spec.linearity_m)
}

fn get_probe(r: &mut Reader<'_>) -> Result<ProbeCalibration, CodecError> {
    Ok(ProbeCalibration {
        zero_counts: r.f32()?,
        metres_per_count: r.f32()?,
        spec: ProbeSpec {
            min_m: r.f32()?,
            max_m: r.f32()?,
            linearity_m: r.f32()?,
        },
    })
}

impl Checkpoint for SensorCalibration {
    const KIND: u8 = kind::CALIBRATION;
    const VERSION: u16 = 1;
    const SIZE: usize = LOAD_SIZE + MISALIGNMENT_SIZE + SPEED_SIZE;

    fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError> {
        let l = &self.load;
        w.u8(channel_code(l.channel))?;
        w.f32(l.zero_counts)?;
        w.f32(l.newtons_per_count)?;
        w.f32(l.min_newtons)?;
        w.f32(l.max_newtons)?;
        let m = &self.misalignment;
        put_probe(w, &m.probe1)?;
        put_probe(w, &m.probe2)?;
        w.f32(m.span_m)?;
        w.f32(m.zero_offset_m)?;
        // A missing tachometer is written as zeros: fixed size either way.
        let s = self.speed.unwrap_or(SpeedCalibration {
            pulses_per_rev: 0,
            radius_m: 0.0,
            max_speed_m_s: 0.0,
        });
        w.bool(self.speed.is_some())?;
        w.u32(s.pulses_per_rev)?;
        w.f32(s.radius_m)?;
        w.f32(s.max_speed_m_s)
    }

    fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError> {
        let load = LoadCalibration {
            channel: channel(r.u8()?)?,
            zero_counts: r.f32()?,
            newtons_per_count: r.f32()?,
            min_newtons: r.f32()?,
            max_newtons: r.f32()?,
        };
        let misalignment = MisalignmentCalibration {
            probe1: get_probe(r)?,
            probe2: get_probe(r)?,
            span_m: r.f32()?,
            zero_offset_m: r.f32()?,
        };
        let has_speed = r.bool()?;
        let speed = SpeedCalibration {
            pulses_per_rev: r.u32()?,
            radius_m: r.f32()?,
            max_speed_m_s: r.f32()?,
        };
        let invalid = |_| CodecError::InvalidValue;
        load.validate().map_err(invalid)?;
        misalignment.validate().map_err(invalid)?;
        if has_speed {
            speed.validate().map_err(invalid)?;
        } else if speed.pulses_per_rev != 0
            || speed.radius_m.to_bits() != 0
            || speed.max_speed_m_s.to_bits() != 0
        {
            // No tachometer was written as zeros, and nothing else.
            return Err(CodecError::InvalidValue);
        }
        Ok(SensorCalibration {
            load,
            misalignment,
            speed: has_speed.then_some(speed),
        })
    }
}
