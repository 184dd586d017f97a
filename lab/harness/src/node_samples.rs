//! The samples `minimal_node` and the Modbus images all process, so that what the
//! Modbus images add is the server (and its storage) alone; the requests they take.

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

/// A request frame for unit 1: `pdu`, then its CRC, in `buf`; its length.
pub fn frame(buf: &mut [u8; 256], pdu: &[u8]) -> usize {
    buf[0] = 1;
    buf[1..=pdu.len()].copy_from_slice(pdu);
    let n = pdu.len() + 1;
    let crc = misalign::modbus::crc16(&buf[..n]).to_le_bytes();
    buf[n..n + 2].copy_from_slice(&crc);
    n + 2
}

/// A function-16 request for unit 1 in `buf`: 20 samples (time, P, phi: 6 registers
/// each) from holding register `sample_0_time_ms`, one a second after `time_ms`, at
/// the loads above and the fourth angle; its length (249 bytes). Built in place (a
/// PDU buffer beside it would be the image's stack, not the node's).
pub fn samples_request(buf: &mut [u8; 256], time_ms: u32) -> usize {
    let start = misalign::modbus::map::SAMPLES_ADDRESS.to_be_bytes();
    buf[..7].copy_from_slice(&[1, 16, start[0], start[1], 0, 120, 240]);
    for k in 0..20u32 {
        let load = crate::io::read(&LOADS[(k % 8) as usize]);
        let phi = crate::io::read(&ANGLES[3]);
        let words = [time_ms + (k + 1) * 1000, load.to_bits(), phi.to_bits()];
        for (w, x) in words.iter().enumerate() {
            let at = 7 + k as usize * 12 + w * 4;
            buf[at..at + 4].copy_from_slice(&x.to_be_bytes());
        }
    }
    let crc = misalign::modbus::crc16(&buf[..247]).to_le_bytes();
    buf[247..249].copy_from_slice(&crc);
    249
}
