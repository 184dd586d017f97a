//! Test builds only (feature `_power-cut`, never in a shipped image): the power cut a
//! test plans, read through semihosting at the start of each flash operation of the
//! node. The plan is a file on the host named as the image (QEMU's `-kernel` path, the
//! image's semihosting command line) with `.cut` added, holding `commit N`, `push N` or
//! `ack N`: the node resets itself after N points (bytes written, words erased) of the
//! next such operation (`ram_flash::armed`), as a power cut there would. The node
//! removes the file as it arms the cut, so that it does not cut again after the reset.
//! `tests/modbus/test_power_cut.py` plans the cuts.

use crate::ram_flash::armed;
use core::ffi::CStr;
use semihosting::fd::AsFd;
use semihosting::sys::arm_compat::{
    OpenMode, sys_get_cmdline_uninit, sys_open, sys_read_orig, sys_remove,
};

/// A flash operation of the node.
#[derive(Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum Op {
    /// The committed configuration's image written.
    Commit,
    /// An event pushed onto the queue.
    Push,
    /// An acknowledgement written to the queue.
    Ack,
}

impl Op {
    fn word(self) -> &'static [u8] {
        match self {
            Op::Commit => b"commit",
            Op::Push => b"push",
            Op::Ack => b"ack",
        }
    }
}

/// Arms the cut if the test planned one for `op` (then [`disarm`] after it).
pub fn arm_if_planned(op: Op) {
    let mut line = [core::mem::MaybeUninit::uninit(); 256];
    let Ok(line) = sys_get_cmdline_uninit(&mut line) else {
        return;
    };
    // The image's path (the first word), then `.cut` and a NUL.
    let image = line.split(|&b| b == b' ').next().unwrap_or(&[]);
    let mut path = [0u8; 260];
    let Some(dest) = path.get_mut(..image.len() + 4) else {
        return;
    };
    dest[..image.len()].copy_from_slice(image);
    dest[image.len()..].copy_from_slice(b".cut");
    let Ok(path) = CStr::from_bytes_until_nul(&path) else {
        return;
    };
    let Ok(file) = sys_open(path, OpenMode::RDONLY) else {
        return;
    };
    let mut text = [0u8; 32];
    let n = sys_read_orig(file.as_fd(), &mut text).unwrap_or(0);
    drop(file);
    let mut words = text[..n.min(text.len())]
        .split(|b| b.is_ascii_whitespace())
        .filter(|w| !w.is_empty());
    if words.next() != Some(op.word()) {
        return;
    }
    let Some(done) = words
        .next()
        .and_then(|w| core::str::from_utf8(w).ok())
        .and_then(|w| w.parse::<u32>().ok())
    else {
        return;
    };
    if sys_remove(path).is_ok() {
        defmt::println!("power cut: after {=u32} points of this {}", done, op);
        armed::arm(done);
    }
}

/// No cut after the operation (it completed before its cut point).
pub fn disarm() {
    armed::disarm();
}
