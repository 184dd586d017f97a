//! [`ConfigImage`]: a configuration committed over a fieldbus, kept as the bytes its
//! server gave (`misalign::modbus::Server::take_committed`, [`kind::COMMITTED_CONFIG`]),
//! so that the storage layer depends on no fieldbus. The record around it is the
//! checkpoints' own ([`codec`](super::codec)): magic, kind, version, length, CRC-32;
//! one key of the [`Store`](super::Store)'s map, so a new image is appended and the old
//! one stays the one restored until the new one is whole on the flash: a power loss at
//! any point of a commit's write leaves the old configuration or the new, never a mix.
//! What the bytes mean (and whether they are a configuration the node can run) the
//! server checks when it is handed them at boot (`Server::restore`).

use super::{Checkpoint, CodecError, Reader, Writer, kind};

/// A committed configuration's image of `N` bytes (for the Modbus server,
/// `misalign::modbus::IMAGE_LEN`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ConfigImage<const N: usize>(pub [u8; N]);

impl<const N: usize> ConfigImage<N> {
    /// An image of zeros, to be filled by the server.
    #[must_use]
    pub const fn new() -> Self {
        ConfigImage([0; N])
    }
}

impl<const N: usize> Default for ConfigImage<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Checkpoint for ConfigImage<N> {
    const KIND: u8 = kind::COMMITTED_CONFIG;
    const VERSION: u16 = 1;
    const SIZE: usize = N;

    fn encode(&self, w: &mut Writer<'_>) -> Result<(), CodecError> {
        w.bytes(&self.0)
    }

    fn decode(r: &mut Reader<'_>) -> Result<Self, CodecError> {
        Ok(ConfigImage(r.array::<N>()?))
    }

    fn decode_into(&mut self, r: &mut Reader<'_>) -> Result<(), CodecError> {
        self.0 = r.array::<N>()?;
        Ok(())
    }
}
