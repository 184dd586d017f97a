//! The ADS1115 (16-bit, I2C) as an [`Adc`], through the maintained `ads1x1x` crate
//! (feature `ads1x1x`): its one-shot `read` is non-blocking, and this adapter polls it
//! a bounded number of times with a delay in between.
//!
//! Configure the driver first (full-scale range, data rate) through `ads1x1x` itself,
//! then hand it over:
//!
//! ```
//! # use embedded_hal_mock::eh1::{delay::NoopDelay, i2c::Mock};
//! # let i2c = Mock::new(&[]);
//! use ads1x1x::{Ads1x1x, TargetAddr};
//! use misalign::sensors::{Adc, Timeout, ads1x1x::{Ads1115, Ads1115Channel}};
//!
//! let driver = Ads1x1x::new_ads1115(i2c, TargetAddr::default());
//! let adc = Ads1115::new(driver, NoopDelay::new(), Timeout::ADS1115_128SPS);
//! assert_eq!(adc.rails().max, 32767);
//! # let mut i2c = adc.release().0.destroy_ads1115();
//! # i2c.done();
//! ```
//!
//! An unplugged ADS1115 does not acknowledge its address: that is a bus error
//! ([`FaultKind::Bus`](super::FaultKind::Bus)). An unplugged *probe* leaves the input
//! floating or pulled to a rail: saturated or stuck codes.

use ads1x1x::channel::{
    DifferentialA0A1, DifferentialA0A3, DifferentialA1A3, DifferentialA2A3, SingleA0, SingleA1,
    SingleA2, SingleA3,
};
use ads1x1x::{Ads1x1x, ic, mode};
use embedded_hal::delay::DelayNs;
use embedded_hal::i2c::I2c;

use super::{Adc, AdcError, Rails, Timeout};

/// The `ads1x1x` driver of an ADS1115 in one-shot mode.
pub type Ads1115Driver<I2C> = Ads1x1x<I2C, ic::Ads1115, ic::Resolution16Bit, mode::OneShot>;

/// An ADS1115 input (the multiplexer setting).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Ads1115Channel {
    /// AIN0 against GND.
    A0,
    /// AIN1 against GND.
    A1,
    /// AIN2 against GND.
    A2,
    /// AIN3 against GND.
    A3,
    /// AIN0 against AIN1.
    A0A1,
    /// AIN0 against AIN3.
    A0A3,
    /// AIN1 against AIN3.
    A1A3,
    /// AIN2 against AIN3.
    A2A3,
}

/// An ADS1115 on I2C with a delay for the bounded wait. (Not `Debug`: the `ads1x1x`
/// driver is not.)
pub struct Ads1115<I2C, D> {
    driver: Ads1115Driver<I2C>,
    delay: D,
    timeout: Timeout,
}

impl<I2C: I2c, D: DelayNs> Ads1115<I2C, D> {
    /// The adapter around a configured driver.
    pub fn new(driver: Ads1115Driver<I2C>, delay: D, timeout: Timeout) -> Self {
        Ads1115 {
            driver,
            delay,
            timeout,
        }
    }

    /// The driver, to change its settings.
    pub fn driver_mut(&mut self) -> &mut Ads1115Driver<I2C> {
        &mut self.driver
    }

    /// Gives the driver and the delay back.
    pub fn release(self) -> (Ads1115Driver<I2C>, D) {
        (self.driver, self.delay)
    }

    fn poll(&mut self, channel: Ads1115Channel) -> nb::Result<i16, ads1x1x::Error<I2C::Error>> {
        let d = &mut self.driver;
        match channel {
            Ads1115Channel::A0 => d.read(SingleA0),
            Ads1115Channel::A1 => d.read(SingleA1),
            Ads1115Channel::A2 => d.read(SingleA2),
            Ads1115Channel::A3 => d.read(SingleA3),
            Ads1115Channel::A0A1 => d.read(DifferentialA0A1),
            Ads1115Channel::A0A3 => d.read(DifferentialA0A3),
            Ads1115Channel::A1A3 => d.read(DifferentialA1A3),
            Ads1115Channel::A2A3 => d.read(DifferentialA2A3),
        }
    }
}

impl<I2C: I2c, D: DelayNs> Adc for Ads1115<I2C, D> {
    type Channel = Ads1115Channel;
    type Error = ads1x1x::Error<I2C::Error>;

    /// -32768 and 32767.
    fn rails(&self) -> Rails {
        Rails {
            min: i16::MIN.into(),
            max: i16::MAX.into(),
        }
    }

    /// Starts a one-shot conversion on `channel` and polls for it at most
    /// `timeout.polls` times (the first poll only starts the conversion).
    fn read(&mut self, channel: Ads1115Channel) -> Result<i32, AdcError<Self::Error>> {
        for _ in 0..self.timeout.polls.max(1) {
            match self.poll(channel) {
                Ok(raw) => return Ok(raw.into()),
                Err(nb::Error::WouldBlock) => self.delay.delay_us(self.timeout.interval_us),
                Err(nb::Error::Other(e)) => return Err(AdcError::Bus(e)),
            }
        }
        Err(AdcError::Timeout)
    }
}
