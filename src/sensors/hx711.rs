//! A small HX711 driver (24-bit bridge ADC, two GPIO pins and a delay) that never waits
//! without bound. Why not the `hx711` or `loadcell` crates: see the module docs of
//! [`sensors`](super).
//!
//! The protocol (HX711 datasheet): DOUT goes low when a conversion is ready; 24 clock
//! pulses on PD_SCK shift it out, most significant bit first, two's complement; 1 to 3
//! more pulses select the channel and gain of the *next* conversion; PD_SCK held high
//! for more than 60 µs powers the chip down, and it wakes up on channel A, gain 128.

use core::fmt;

use embedded_hal::delay::DelayNs;
use embedded_hal::digital::{InputPin, OutputPin};

use super::{Adc, AdcError, Rails, Timeout};

/// The HX711's input and gain, set for the next conversion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Hx711Channel {
    /// Channel A, gain 128 (full scale +-20 mV at 5 V excitation): the load-cell
    /// default, and the chip's state after power-up.
    #[default]
    A128,
    /// Channel A, gain 64 (full scale +-40 mV).
    A64,
    /// Channel B, gain 32 (full scale +-80 mV).
    B32,
}

impl Hx711Channel {
    /// The clock pulses after the 24 data bits that select this channel and gain.
    pub const fn extra_pulses(self) -> u8 {
        match self {
            Hx711Channel::A128 => 1,
            Hx711Channel::B32 => 2,
            Hx711Channel::A64 => 3,
        }
    }
}

/// A pin error of the [`Hx711`] driver.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PinError<EIn, EOut> {
    /// Reading DOUT failed.
    Dout(EIn),
    /// Driving PD_SCK failed.
    Sck(EOut),
}

impl<EIn: fmt::Debug, EOut: fmt::Debug> fmt::Display for PinError<EIn, EOut> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PinError::Dout(e) => write!(f, "HX711 DOUT read failed: {e:?}"),
            PinError::Sck(e) => write!(f, "HX711 PD_SCK drive failed: {e:?}"),
        }
    }
}

impl<EIn: fmt::Debug, EOut: fmt::Debug> core::error::Error for PinError<EIn, EOut> {}

/// The HX711 on two GPIO pins: DOUT (input) and PD_SCK (output), with a delay.
///
/// Reads are bounded by a [`Timeout`]: a chip that never pulls DOUT low (unplugged,
/// unpowered) gives [`AdcError::Timeout`] after `polls * interval_us` µs. Changing the
/// channel costs one conversion (the one under way still has the old gain and is
/// discarded), so the timeout should cover two conversion periods
/// ([`Timeout::HX711_10SPS`] does at 10 samples/s).
///
/// PD_SCK must not stay high for 60 µs inside a read, or the chip powers down: an
/// interrupt handler that can run that long should be masked around [`Adc::read`].
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Hx711<Dout, Sck, D> {
    dout: Dout,
    sck: Sck,
    delay: D,
    timeout: Timeout,
    /// The channel and gain of the conversion under way.
    pending: Hx711Channel,
    /// A pin failed in the middle of a read: the chip is at an unknown bit, so the
    /// next attempt power-cycles it first.
    resync: bool,
}

impl<Dout, Sck, D> Hx711<Dout, Sck, D>
where
    Dout: InputPin,
    Sck: OutputPin,
    D: DelayNs,
{
    /// The driver on these pins. It drives PD_SCK low (the chip runs) and does not wait
    /// for a conversion; after power-up the chip converts channel A at gain 128.
    pub fn new(
        dout: Dout,
        mut sck: Sck,
        delay: D,
        timeout: Timeout,
    ) -> Result<Self, PinError<Dout::Error, Sck::Error>> {
        sck.set_low().map_err(PinError::Sck)?;
        Ok(Hx711 {
            dout,
            sck,
            delay,
            timeout,
            pending: Hx711Channel::A128,
            resync: false,
        })
    }

    /// The bounded wait of [`Adc::read`].
    pub fn timeout(&self) -> Timeout {
        self.timeout
    }

    /// Sets the bounded wait of [`Adc::read`].
    pub fn set_timeout(&mut self, timeout: Timeout) {
        self.timeout = timeout;
    }

    /// Whether DOUT is low: a conversion is ready.
    pub fn is_ready(&mut self) -> Result<bool, PinError<Dout::Error, Sck::Error>> {
        self.dout.is_low().map_err(PinError::Dout)
    }

    /// One attempt: `None` if no conversion is ready, or if the ready one was made with
    /// another channel or gain than `channel` (it is clocked out, discarded, and the
    /// next conversion is set to `channel`). After a pin error in the middle of a read,
    /// the next attempt power-cycles the chip (and gives `None`), so that a half-read
    /// word is never taken for a conversion.
    pub fn try_read(
        &mut self,
        channel: Hx711Channel,
    ) -> Result<Option<i32>, PinError<Dout::Error, Sck::Error>> {
        if self.resync {
            self.power_down()?;
            self.power_up()?;
            self.resync = false;
            return Ok(None);
        }
        if !self.is_ready()? {
            return Ok(None);
        }
        self.resync = true;
        // DOUT low to the first rising edge: at least 0.1 us (T1).
        self.delay.delay_us(1);
        let mut bits: u32 = 0;
        for _ in 0..24 {
            let high = self.pulse()?;
            bits = (bits << 1) | u32::from(high);
        }
        for _ in 0..channel.extra_pulses() {
            self.pulse()?;
        }
        self.resync = false;
        let made_with = core::mem::replace(&mut self.pending, channel);
        // Sign-extend the 24-bit two's complement code.
        let raw = ((bits << 8) as i32) >> 8;
        Ok((made_with == channel).then_some(raw))
    }

    /// One PD_SCK pulse (1 µs high, 1 µs low); DOUT is sampled while high.
    fn pulse(&mut self) -> Result<bool, PinError<Dout::Error, Sck::Error>> {
        self.sck.set_high().map_err(PinError::Sck)?;
        self.delay.delay_us(1);
        let high = self.dout.is_high().map_err(PinError::Dout);
        // Bring PD_SCK low even when DOUT failed, so the chip is not left powering down.
        self.sck.set_low().map_err(PinError::Sck)?;
        self.delay.delay_us(1);
        high
    }

    /// Powers the chip down (PD_SCK high for 70 µs).
    pub fn power_down(&mut self) -> Result<(), PinError<Dout::Error, Sck::Error>> {
        self.sck.set_high().map_err(PinError::Sck)?;
        self.delay.delay_us(70);
        Ok(())
    }

    /// Wakes the chip up (PD_SCK low); it starts over on channel A, gain 128.
    pub fn power_up(&mut self) -> Result<(), PinError<Dout::Error, Sck::Error>> {
        self.sck.set_low().map_err(PinError::Sck)?;
        self.pending = Hx711Channel::A128;
        Ok(())
    }

    /// Gives the pins and the delay back.
    pub fn release(self) -> (Dout, Sck, D) {
        (self.dout, self.sck, self.delay)
    }
}

impl<Dout, Sck, D> Adc for Hx711<Dout, Sck, D>
where
    Dout: InputPin,
    Sck: OutputPin,
    D: DelayNs,
{
    type Channel = Hx711Channel;
    type Error = PinError<Dout::Error, Sck::Error>;

    /// -2^23 and 2^23 - 1.
    fn rails(&self) -> Rails {
        Rails {
            min: -(1 << 23),
            max: (1 << 23) - 1,
        }
    }

    fn read(&mut self, channel: Hx711Channel) -> Result<i32, AdcError<Self::Error>> {
        for _ in 0..self.timeout.polls.max(1) {
            if let Some(raw) = self.try_read(channel).map_err(AdcError::Bus)? {
                return Ok(raw);
            }
            self.delay.delay_us(self.timeout.interval_us);
        }
        Err(AdcError::Timeout)
    }
}
