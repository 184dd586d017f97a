//! The boards' UARTs by their registers, polled (no interrupts, no DMA), 8N1 at
//! 115200 baud at start, then at the line settings in force ([`Uart::configure`]):
//! what QEMU's boards give serial0, and enough for the real chips. (QEMU's serial0
//! over TCP carries bytes at any rate: the registers are written, the bytes flow.)
//!
//! - CMSDK APB UART0 at 0x4000_4000 on the MPS2 boards (mps2-an385 Cortex-M3,
//!   mps2-an386 Cortex-M4F, mps2-an500 Cortex-M7): a one-byte receive buffer.
//! - The nRF51's UART at 0x4000_2000 on the micro:bit (Cortex-M0): `ENABLE = 4`, then
//!   the STARTRX and STARTTX tasks; an event per byte received and sent.
//! - USART1 at 0x4001_1000 on the STM32F405 (`netduinoplus2`; PA9/PA10, AF7 on a real
//!   board): only RXNE, TXE and TC are used, as QEMU models no more; the clock is the
//!   16 MHz HSI a reset leaves.
//!
//! [`Uart::for_this_board`] picks the board from the core (CPUID) and where the image
//! is linked (flash at 0x0800_0000 is the STM32 layout, `lab/harness/boards/stm32f4.x`).
//! Each implements the `embedded-io` 0.7 traits the library's `Server::poll` takes, as
//! a HAL's UART does. The only `unsafe` of the example is here, in [`Reg`]'s two
//! accessors.

use core::ptr::{read_volatile, write_volatile};

/// One 32-bit memory-mapped register, at an address of the tables below only.
#[derive(Clone, Copy)]
struct Reg(usize);

impl Reg {
    fn read(self) -> u32 {
        // SAFETY: every `Reg` is built in this module from a board's datasheet address
        // of a 4-byte-aligned peripheral register, mapped for the whole run; volatile,
        // as the hardware changes it (and a read of a data register pops a byte, which
        // the callers intend).
        unsafe { read_volatile(self.0 as *const u32) }
    }

    fn write(self, value: u32) {
        // SAFETY: as in `read`: a valid, aligned peripheral register; writing it has
        // no effect on memory the program owns.
        unsafe { write_volatile(self.0 as *mut u32, value) }
    }
}

const BAUD: u32 = 115_200;

/// CMSDK APB UART0 (ARM DDI 0479C, 4.6): DATA, STATE (bit 0 TX full, bit 1 RX full),
/// CTRL (bit 0 TX enable, bit 1 RX enable), BAUDDIV.
mod cmsdk {
    use super::Reg;
    const BASE: usize = 0x4000_4000;
    pub const DATA: Reg = Reg(BASE);
    pub const STATE: Reg = Reg(BASE + 0x04);
    pub const CTRL: Reg = Reg(BASE + 0x08);
    pub const BAUDDIV: Reg = Reg(BASE + 0x10);
    pub const TX_FULL: u32 = 1 << 0;
    pub const RX_FULL: u32 = 1 << 1;
    /// The MPS2 boards' peripheral clock, Hz.
    pub const CLOCK: u32 = 25_000_000;
}

/// nRF51 UART (nRF51 Series Reference Manual v3.0, 29.10).
mod nrf51 {
    use super::Reg;
    const BASE: usize = 0x4000_2000;
    pub const STARTRX: Reg = Reg(BASE);
    pub const STARTTX: Reg = Reg(BASE + 0x008);
    pub const RXDRDY: Reg = Reg(BASE + 0x108);
    pub const TXDRDY: Reg = Reg(BASE + 0x11C);
    pub const ENABLE: Reg = Reg(BASE + 0x500);
    pub const PSELTXD: Reg = Reg(BASE + 0x50C);
    pub const PSELRXD: Reg = Reg(BASE + 0x514);
    pub const RXD: Reg = Reg(BASE + 0x518);
    pub const TXD: Reg = Reg(BASE + 0x51C);
    pub const BAUDRATE: Reg = Reg(BASE + 0x524);
    pub const CONFIG: Reg = Reg(BASE + 0x56C);
    /// BAUDRATE's value for 115200 baud.
    pub const BAUD_115200: u32 = 0x01D7_E000;
    /// BAUDRATE's values of the line's rates (the manual's table, 29.10.11).
    pub const BAUDS: [(u32, u32); 5] = [
        (9_600, 0x0027_5000),
        (19_200, 0x004E_A000),
        (38_400, 0x009D_5000),
        (57_600, 0x00EB_F000),
        (115_200, BAUD_115200),
    ];
    /// CONFIG's PARITY field (bits 3:1): 0b111 includes an even parity bit.
    pub const PARITY_EVEN: u32 = 0b111 << 1;
    /// The micro:bit's interface-chip UART pins: TX P0.24, RX P0.25.
    pub const TX_PIN: u32 = 24;
    pub const RX_PIN: u32 = 25;
}

/// STM32F405 USART1 (RM0090, 30.6) and what a real chip needs before it: the clocks
/// of GPIOA and USART1, PA9/PA10 in alternate function 7.
mod stm32 {
    use super::Reg;
    const BASE: usize = 0x4001_1000;
    pub const SR: Reg = Reg(BASE);
    pub const DR: Reg = Reg(BASE + 0x04);
    pub const BRR: Reg = Reg(BASE + 0x08);
    pub const CR1: Reg = Reg(BASE + 0x0C);
    pub const CR2: Reg = Reg(BASE + 0x10);
    /// CR1: M (9 data bits: 8 and the parity bit), PCE (parity on), PS (odd).
    pub const M: u32 = 1 << 12;
    pub const PCE: u32 = 1 << 10;
    pub const PS: u32 = 1 << 9;
    /// CR2's STOP field (bits 13:12): 0b10, two stop bits.
    pub const STOP_2: u32 = 0b10 << 12;
    pub const RXNE: u32 = 1 << 5;
    pub const TC: u32 = 1 << 6;
    pub const TXE: u32 = 1 << 7;
    /// CR1: UE, TE, RE.
    pub const ENABLE: u32 = (1 << 13) | (1 << 3) | (1 << 2);
    pub const RCC_AHB1ENR: Reg = Reg(0x4002_3830);
    pub const RCC_APB2ENR: Reg = Reg(0x4002_3844);
    pub const GPIOA_MODER: Reg = Reg(0x4002_0000);
    pub const GPIOA_AFRH: Reg = Reg(0x4002_0024);
    /// The HSI a reset leaves as the system and APB2 clock, Hz.
    pub const CLOCK: u32 = 16_000_000;
}

/// The board's UART.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum Uart {
    /// MPS2: CMSDK UART0.
    Cmsdk,
    /// micro:bit: the nRF51's UART.
    Nrf51,
    /// STM32F405: USART1.
    Stm32,
}

impl Uart {
    /// The UART of the board this image runs on, started: the micro:bit's on a
    /// Cortex-M0 (`cpuid`'s part number 0xC20), USART1 where the image is linked for an
    /// STM32 (flash at 0x0800_0000), else the MPS2 boards' UART0.
    pub fn for_this_board(cpuid: &cortex_m::peripheral::CPUID) -> Self {
        let part = (cpuid.base.read() >> 4) & 0xFFF;
        let linked_at = Self::for_this_board as fn(&cortex_m::peripheral::CPUID) -> Self as usize;
        let uart = if part == 0xC20 {
            Uart::Nrf51
        } else if (0x0800_0000..0x1000_0000).contains(&linked_at) {
            Uart::Stm32
        } else {
            Uart::Cmsdk
        };
        uart.start();
        uart
    }

    fn start(self) {
        match self {
            Uart::Cmsdk => {
                cmsdk::BAUDDIV.write(cmsdk::CLOCK / BAUD);
                cmsdk::CTRL.write(0b11);
            }
            Uart::Nrf51 => {
                nrf51::PSELTXD.write(nrf51::TX_PIN);
                nrf51::PSELRXD.write(nrf51::RX_PIN);
                nrf51::BAUDRATE.write(nrf51::BAUD_115200);
                nrf51::ENABLE.write(4);
                nrf51::STARTRX.write(1);
                nrf51::STARTTX.write(1);
            }
            Uart::Stm32 => {
                stm32::RCC_AHB1ENR.write(stm32::RCC_AHB1ENR.read() | 1);
                stm32::RCC_APB2ENR.write(stm32::RCC_APB2ENR.read() | 1 << 4);
                // PA9, PA10: alternate function (MODER 0b10), AF7 (USART1).
                let moder = stm32::GPIOA_MODER.read() & !(0b1111 << 18);
                stm32::GPIOA_MODER.write(moder | 0b1010 << 18);
                let afrh = stm32::GPIOA_AFRH.read() & !(0xFF << 4);
                stm32::GPIOA_AFRH.write(afrh | 0x77 << 4);
                stm32::BRR.write(stm32::CLOCK.div_ceil(BAUD));
                stm32::CR1.write(stm32::ENABLE);
            }
        }
    }
}

/// What [`Uart::configure`] wrote: the baud rate's register and its value, the
/// frame's (parity, stop bits) register and its value, if the UART has one; and
/// whether the UART could take the parity and stop bits asked.
#[derive(Clone, Copy, defmt::Format)]
pub struct Configured {
    pub rate: (&'static str, u32),
    pub frame: Option<(&'static str, u32)>,
    pub as_asked: bool,
}

impl Uart {
    /// Sets the UART to `baud` bits per second and `parity` (8 data bits; two stop
    /// bits without parity, one with it): the CMSDK UART's BAUDDIV (it has no parity
    /// and one stop bit only), the nRF51's BAUDRATE and CONFIG (even parity only, one
    /// stop bit only), the STM32's BRR, CR1 and CR2. A rate the nRF51's table does not
    /// hold leaves its BAUDRATE as it was.
    pub fn configure(self, baud: u32, parity: misalign::modbus::Parity) -> Configured {
        use misalign::modbus::Parity;
        let baud = baud.max(1);
        match self {
            Uart::Cmsdk => {
                let div = cmsdk::CLOCK / baud;
                cmsdk::BAUDDIV.write(div);
                Configured {
                    rate: ("BAUDDIV", div),
                    frame: None,
                    as_asked: false,
                }
            }
            Uart::Nrf51 => {
                let rate = nrf51::BAUDS
                    .iter()
                    .find(|(b, _)| *b == baud)
                    .map(|(_, v)| *v);
                if let Some(v) = rate {
                    nrf51::BAUDRATE.write(v);
                }
                let config = if parity == Parity::Even {
                    nrf51::PARITY_EVEN
                } else {
                    0
                };
                nrf51::CONFIG.write(config);
                Configured {
                    rate: ("BAUDRATE", nrf51::BAUDRATE.read()),
                    frame: Some(("CONFIG", config)),
                    as_asked: rate.is_some() && parity == Parity::Even,
                }
            }
            Uart::Stm32 => {
                let brr = stm32::CLOCK.div_ceil(baud);
                let cr1 = stm32::ENABLE
                    | match parity {
                        Parity::None => 0,
                        Parity::Odd => stm32::M | stm32::PCE | stm32::PS,
                        Parity::Even => stm32::M | stm32::PCE,
                    };
                let cr2 = if parity == Parity::None {
                    stm32::STOP_2
                } else {
                    0
                };
                // The frame's format is changed with the USART disabled (RM0090, 30.6).
                while stm32::SR.read() & stm32::TC == 0 {}
                stm32::CR1.write(0);
                stm32::BRR.write(brr);
                stm32::CR2.write(cr2);
                stm32::CR1.write(cr1);
                Configured {
                    rate: ("BRR", brr),
                    frame: Some(("CR1", cr1)),
                    as_asked: true,
                }
            }
        }
    }

    /// The silence that ends a frame, in core clock ticks (SysTick's). Not the 3.5
    /// character times of a real line (1750 us at this baud): in QEMU the line is a
    /// TCP socket whose bytes QEMU's I/O thread hands over one by one, and while that
    /// thread waits for the host's scheduler the guest runs on, so one frame's bytes
    /// can arrive many milliseconds of virtual time apart (at 100 ms, one request in
    /// a few thousand lost its frame here on a loaded host); a master leaves far
    /// more between requests. One second of virtual time.
    pub fn silence_ticks(self) -> u32 {
        match self {
            // The MPS2 boards' 25 MHz; the nRF51's 16 MHz; the STM32's HSI, 16 MHz.
            Uart::Cmsdk => 25_000_000,
            Uart::Nrf51 | Uart::Stm32 => 16_000_000,
        }
    }

    /// Whether a received byte waits.
    fn rx_ready(self) -> bool {
        match self {
            Uart::Cmsdk => cmsdk::STATE.read() & cmsdk::RX_FULL != 0,
            Uart::Nrf51 => nrf51::RXDRDY.read() != 0,
            Uart::Stm32 => stm32::SR.read() & stm32::RXNE != 0,
        }
    }

    /// The waiting byte (after [`rx_ready`](Self::rx_ready)).
    fn take(self) -> u8 {
        match self {
            Uart::Cmsdk => cmsdk::DATA.read() as u8,
            Uart::Nrf51 => {
                // Clear the event first: reading RXD raises it again if another byte
                // is waiting.
                nrf51::RXDRDY.write(0);
                nrf51::RXD.read() as u8
            }
            Uart::Stm32 => stm32::DR.read() as u8,
        }
    }

    /// Sends one byte, waiting for room.
    fn put(self, b: u8) {
        match self {
            Uart::Cmsdk => {
                while cmsdk::STATE.read() & cmsdk::TX_FULL != 0 {}
                cmsdk::DATA.write(u32::from(b));
            }
            Uart::Nrf51 => {
                nrf51::TXDRDY.write(0);
                nrf51::TXD.write(u32::from(b));
                while nrf51::TXDRDY.read() == 0 {}
            }
            Uart::Stm32 => {
                while stm32::SR.read() & stm32::TXE == 0 {}
                stm32::DR.write(u32::from(b));
            }
        }
    }
}

impl embedded_io::ErrorType for Uart {
    type Error = core::convert::Infallible;
}

impl embedded_io::ReadReady for Uart {
    fn read_ready(&mut self) -> Result<bool, Self::Error> {
        Ok(self.rx_ready())
    }
}

impl embedded_io::Read for Uart {
    /// Waits for a byte, then takes every byte already waiting, as far as `buf` goes.
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        let mut n = 0;
        for slot in buf.iter_mut() {
            if n > 0 && !self.rx_ready() {
                break;
            }
            while !self.rx_ready() {}
            *slot = self.take();
            n += 1;
        }
        Ok(n)
    }
}

impl embedded_io::Write for Uart {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        for &b in buf {
            self.put(b);
        }
        Ok(buf.len())
    }

    /// Returns once the last stop bit has left (the STM32's TC; the nRF51 waited for
    /// TXDRDY byte by byte; the CMSDK UART says no more than "buffer empty"): an RS-485
    /// transceiver's driver may be released now.
    fn flush(&mut self) -> Result<(), Self::Error> {
        match self {
            Uart::Cmsdk => while cmsdk::STATE.read() & cmsdk::TX_FULL != 0 {},
            Uart::Nrf51 => {}
            Uart::Stm32 => while stm32::SR.read() & stm32::TC == 0 {},
        }
        Ok(())
    }
}
