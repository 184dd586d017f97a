//! The exception codes a Modbus server answers with (the application protocol
//! specification, section 7): the one type the function handlers share.

use core::fmt;

/// An exception code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Exception {
    /// 01: the function is not supported, or not in the server's present state.
    IllegalFunction = 1,
    /// 02: an address outside the map, or not writable as asked.
    IllegalDataAddress = 2,
    /// 03: a quantity, byte count or value outside what the request allows.
    IllegalDataValue = 3,
    /// 04: the server failed while answering (not expected: the answer would not fit
    /// its buffer).
    ServerDeviceFailure = 4,
}

impl fmt::Display for Exception {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Exception::IllegalFunction => "01 illegal function",
            Exception::IllegalDataAddress => "02 illegal data address",
            Exception::IllegalDataValue => "03 illegal data value",
            Exception::ServerDeviceFailure => "04 server device failure",
        })
    }
}
