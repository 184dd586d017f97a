//! Sleeping on the RP2040's timer: alarm 1 (embassy-time's driver has alarm 0) wakes
//! the core from WFI, so that the node sleeps between samples and requests and the
//! drivers' waits (an ADS1115 conversion, an HX711 not yet ready) sleep too.

use embassy_rp::interrupt::{self, InterruptExt};
use embassy_rp::pac;
use embassy_time::Instant;
use embedded_hal::delay::DelayNs;

/// Delays shorter than this (µs) spin: sleeping costs more.
const SPIN_US: u64 = 50;

/// Enables alarm 1's interrupt; once, at boot.
pub fn init() {
    pac::TIMER.inte().modify(|w| w.set_alarm(1, true));
    // SAFETY: its handler below only clears the alarm; no critical section of the
    // node relies on this interrupt being off.
    unsafe { interrupt::TIMER_IRQ_1.enable() };
}

/// Alarm 1's handler (its vector by name, as `bind_interrupts!` binds the HAL's).
#[unsafe(no_mangle)]
extern "C" fn TIMER_IRQ_1() {
    pac::TIMER.intr().write(|w| w.set_alarm(1, true));
}

/// Sleeps until the timer reaches `at_us` or `pending` (checked with interrupts
/// masked, so that an interrupt between the check and the sleep still wakes it)
/// says there is work.
pub fn sleep_until(at_us: u64, pending: &mut dyn FnMut() -> bool) {
    loop {
        let now = Instant::now().as_micros();
        if now >= at_us {
            return;
        }
        if at_us - now <= SPIN_US {
            while Instant::now().as_micros() < at_us {}
            return;
        }
        pac::TIMER.alarm(1).write_value(at_us as u32);
        let woke_for_work = cortex_m::interrupt::free(|_| {
            if pending() {
                return true;
            }
            if Instant::now().as_micros() < at_us {
                cortex_m::asm::wfi();
            }
            false
        });
        if woke_for_work {
            return;
        }
    }
}

/// The drivers' delay: spins below 50 µs, sleeps above.
#[derive(Debug, Clone, Copy)]
pub struct Sleep;

impl DelayNs for Sleep {
    fn delay_ns(&mut self, ns: u32) {
        let until = Instant::now().as_micros() + u64::from(ns).div_ceil(1000);
        sleep_until(until, &mut || false);
    }
}
