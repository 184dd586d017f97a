//! The byte loop over a UART implementing the `embedded-io` 0.7 traits (feature
//! `embedded-io`): a real HAL's UART plugs in unchanged. Neither sees the line's
//! silence: a node whose UART reports an idle line (or that keeps a timer) calls
//! [`Server::idle`] itself.

use super::Server;
use crate::Estimator;
use embedded_io::{Read, ReadReady, Write};

impl<E: Estimator> Server<E> {
    /// Without blocking: takes every byte the UART has ready, then writes the
    /// response if one is due. Returns whether it wrote one.
    ///
    /// # Errors
    /// The UART's.
    pub fn poll<U: Read + ReadReady + Write>(&mut self, uart: &mut U) -> Result<bool, U::Error> {
        let mut buf = [0u8; 16];
        while uart.read_ready()? {
            let n = uart.read(&mut buf)?;
            if n == 0 {
                break;
            }
            for &b in buf.get(..n).unwrap_or(&[]) {
                self.receive(b);
            }
        }
        self.send(uart)
    }

    /// Blocking: reads until a request is answered and writes the answer. Returns
    /// `false` at the end of the input (a read of 0 bytes). Not for store-and-forward,
    /// whose writes wait for `stored` between the request and the answer: `poll` then.
    ///
    /// # Errors
    /// The UART's.
    pub fn serve<U: Read + Write>(&mut self, uart: &mut U) -> Result<bool, U::Error> {
        let mut byte = [0u8; 1];
        loop {
            if uart.read(&mut byte)? == 0 {
                return Ok(false);
            }
            self.receive(byte[0]);
            if self.response().is_some() {
                return self.send(uart);
            }
        }
    }

    /// Writes the due response, if any, and flushes; a UART that takes no byte ends
    /// the attempt (the response is given up, as a master's timeout would).
    fn send<U: Write>(&mut self, uart: &mut U) -> Result<bool, U::Error> {
        let Some(mut rest) = self.response() else {
            return Ok(false);
        };
        while !rest.is_empty() {
            match uart.write(rest)? {
                0 => break,
                n => rest = rest.get(n..).unwrap_or(&[]),
            }
        }
        uart.flush()?;
        self.sent();
        Ok(true)
    }
}
