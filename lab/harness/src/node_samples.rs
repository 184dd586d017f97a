//! The samples `minimal_node` and `modbus_node` both process, so that what the Modbus
//! image adds is the server alone.

/// The load sensor's samples (N), one a second, repeating: about 2.5 kN.
pub static LOADS: [f32; 8] = [
    2410.0, 2530.0, 2475.0, 2610.0, 2555.0, 2420.0, 2490.0, 2535.0,
];
/// The misalignment (rad), one step a minute: a drift through the critical angle
/// (about 0.5 mrad at this load) and back.
pub static ANGLES: [f32; 8] = [
    1.0e-4, 2.5e-4, 4.0e-4, 4.6e-4, 5.5e-4, 7.0e-4, 8.0e-4, 2.0e-4,
];
/// Eight minutes of samples.
pub const SAMPLES: u32 = 480;
