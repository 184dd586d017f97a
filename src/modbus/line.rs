//! The line settings (unit id, baud rate, parity, answer delay, bus timeout): staged
//! and committed with the configuration, applied after the commit's answer is sent,
//! kept only once a master reaches the node at them within
//! [`LINE_CONFIRM_WINDOW_S`], reverted otherwise; and the supervision of the master
//! (the bus timeout). The server owns no UART: the application reads
//! [`Server::line`](super::Server::line) after each [`sent`](super::Server::sent) and
//! [`tick`](super::Server::tick), and sets its UART when it changed.
//!
//! Time is the application's clock ([`Server::tick`](super::Server::tick)): without
//! ticks no change is reverted and no master is lost.

use core::fmt;

/// How long (s) a change of the line settings waits for a request addressed to the
/// node at its new settings before the node goes back to the settings before it.
pub const LINE_CONFIRM_WINDOW_S: u16 = 60;
/// The baud rates a node takes (bits per second).
pub const BAUD_RATES: [u32; 5] = [9_600, 19_200, 38_400, 57_600, 115_200];
/// The longest answer delay (ms).
pub const ANSWER_DELAY_MAX_MS: u16 = 1_000;

/// The parity of the line's characters (`config_parity`): with none, two stop bits, as
/// the Modbus serial line specification asks (11 bits a character either way).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Parity {
    /// 0: no parity bit, two stop bits.
    None = 0,
    /// 1: odd parity, one stop bit.
    Odd = 1,
    /// 2: even parity, one stop bit (the specification's default).
    Even = 2,
}

impl Parity {
    /// The parity of a register's value.
    pub const fn from_code(code: u32) -> Option<Parity> {
        match code {
            0 => Some(Parity::None),
            1 => Some(Parity::Odd),
            2 => Some(Parity::Even),
            _ => None,
        }
    }

    /// Stop bits a character takes: 2 without parity, 1 with it.
    pub const fn stop_bits(self) -> u8 {
        match self {
            Parity::None => 2,
            Parity::Odd | Parity::Even => 1,
        }
    }
}

/// A node's line settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LineSettings {
    /// The unit id (1 to 247).
    pub unit_id: u8,
    /// Bits per second, one of [`BAUD_RATES`].
    pub baud: u32,
    /// The parity.
    pub parity: Parity,
    /// The least time (ms) between a request's end and its answer's start (slow
    /// masters, transceivers that turn the line around slowly); at most
    /// [`ANSWER_DELAY_MAX_MS`].
    pub answer_delay_ms: u16,
    /// The master is lost after this long (s) without a request for this node; 0:
    /// not supervised.
    pub bus_timeout_s: u16,
}

impl LineSettings {
    /// The documented defaults: unit 1, 19200 baud, even parity, no answer delay, no
    /// bus timeout.
    pub const DEFAULT: LineSettings = LineSettings {
        unit_id: super::DEFAULT_UNIT_ID,
        baud: 19_200,
        parity: Parity::Even,
        answer_delay_ms: 0,
        bus_timeout_s: 0,
    };

    /// Whether a node takes them.
    ///
    /// # Errors
    /// The first value it does not take.
    pub fn validate(&self) -> Result<(), LineError> {
        if !(1..=247).contains(&self.unit_id) {
            Err(LineError::UnitId)
        } else if !BAUD_RATES.contains(&self.baud) {
            Err(LineError::Baud)
        } else if self.answer_delay_ms > ANSWER_DELAY_MAX_MS {
            Err(LineError::AnswerDelay)
        } else {
            Ok(())
        }
    }

    /// The silence (us) that ends a frame at this baud rate
    /// ([`silence_us`](super::silence_us)).
    pub const fn silence_us(&self) -> u32 {
        super::silence_us(self.baud)
    }

    /// The value of `f`, as its register's bits.
    pub(crate) fn get(&self, f: LineField) -> u32 {
        match f {
            LineField::UnitId => u32::from(self.unit_id),
            LineField::Baud => self.baud,
            LineField::Parity => self.parity as u32,
            LineField::AnswerDelay => u32::from(self.answer_delay_ms),
            LineField::BusTimeout => u32::from(self.bus_timeout_s),
        }
    }

    /// `f` set to `v`, if `v` is in its domain ([`LineField::takes`]).
    fn with(mut self, f: LineField, v: u32) -> Option<LineSettings> {
        if !f.takes(v) {
            return None;
        }
        match f {
            LineField::UnitId => self.unit_id = v as u8,
            LineField::Baud => self.baud = v,
            LineField::Parity => self.parity = Parity::from_code(v)?,
            LineField::AnswerDelay => self.answer_delay_ms = v as u16,
            LineField::BusTimeout => self.bus_timeout_s = v as u16,
        }
        Some(self)
    }

    /// As 10 bytes in a committed image: unit id, parity, baud (u32), answer delay
    /// (u16), bus timeout (u16), little-endian.
    pub(crate) fn to_bytes(self) -> [u8; LINE_BYTES] {
        let mut b = [0; LINE_BYTES];
        b[0] = self.unit_id;
        b[1] = self.parity as u8;
        b[2..6].copy_from_slice(&self.baud.to_le_bytes());
        b[6..8].copy_from_slice(&self.answer_delay_ms.to_le_bytes());
        b[8..10].copy_from_slice(&self.bus_timeout_s.to_le_bytes());
        b
    }

    /// The settings of [`to_bytes`](Self::to_bytes), if valid.
    pub(crate) fn from_bytes(b: &[u8; LINE_BYTES]) -> Option<LineSettings> {
        let s = LineSettings {
            unit_id: b[0],
            parity: Parity::from_code(u32::from(b[1]))?,
            baud: u32::from_le_bytes([b[2], b[3], b[4], b[5]]),
            answer_delay_ms: u16::from_le_bytes([b[6], b[7]]),
            bus_timeout_s: u16::from_le_bytes([b[8], b[9]]),
        };
        s.validate().ok().map(|()| s)
    }
}

impl Default for LineSettings {
    fn default() -> Self {
        LineSettings::DEFAULT
    }
}

/// Bytes of the line settings in a committed image.
pub(crate) const LINE_BYTES: usize = 10;

/// A value of the line settings a node does not take.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LineError {
    /// The unit id is 0 (broadcast) or above 247 (reserved).
    UnitId,
    /// A baud rate not in [`BAUD_RATES`].
    Baud,
    /// An answer delay above [`ANSWER_DELAY_MAX_MS`].
    AnswerDelay,
}

impl fmt::Display for LineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            LineError::UnitId => "the unit id must be 1 to 247",
            LineError::Baud => "the baud rate must be 9600, 19200, 38400, 57600 or 115200",
            LineError::AnswerDelay => "the answer delay must be at most 1000 ms",
        })
    }
}

impl core::error::Error for LineError {}

/// One value of the line settings' registers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LineField {
    UnitId,
    Baud,
    Parity,
    AnswerDelay,
    BusTimeout,
}

impl LineField {
    /// Whether a master may write `v` (the map's domain).
    pub(crate) fn takes(self, v: u32) -> bool {
        match self {
            LineField::UnitId => (1..=247).contains(&v),
            LineField::Baud => BAUD_RATES.contains(&v),
            LineField::Parity => v <= 2,
            LineField::AnswerDelay => v <= u32::from(ANSWER_DELAY_MAX_MS),
            LineField::BusTimeout => v <= 0xFFFF,
        }
    }
}

/// What changed the link's state, for the server to raise as an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Raised {
    Nothing,
    Reverted,
    MasterLost,
    MasterBack,
}

/// A change of the line settings on its way.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Change {
    None,
    /// Committed: in force once the commit's answer is sent.
    Due(LineSettings),
    /// In force, waiting for a request at it; `left_ms` of the window left.
    Confirming {
        left_ms: u32,
    },
}

/// The line settings' state in a server.
#[derive(Debug, Clone)]
pub(crate) struct Line {
    /// In force.
    active: LineSettings,
    /// What a reset starts with: the confirmed settings (the committed image's).
    kept: LineSettings,
    staged: Option<LineSettings>,
    change: Change,
    /// Time since the last request for this node (ms), saturated.
    silent_ms: u32,
    last_tick: Option<u32>,
    master_lost: bool,
    reverts: u32,
}

impl Line {
    pub(crate) const fn new(settings: LineSettings) -> Self {
        Line {
            active: settings,
            kept: settings,
            staged: None,
            change: Change::None,
            silent_ms: 0,
            last_tick: None,
            master_lost: false,
            reverts: 0,
        }
    }

    /// In force.
    pub(crate) fn active(&self) -> LineSettings {
        self.active
    }

    /// What the committed image keeps.
    pub(crate) fn kept(&self) -> LineSettings {
        self.kept
    }

    /// Settings restored from the committed image at boot: in force and kept.
    pub(crate) fn restore(&mut self, settings: LineSettings) {
        *self = Line::new(settings);
    }

    pub(crate) fn staged_value(&self, f: LineField) -> u32 {
        self.staged.unwrap_or(self.active).get(f)
    }

    /// A write into the staged settings (the guard passed); false if `v` is not in
    /// the field's domain (nothing written).
    pub(crate) fn write_staged(&mut self, f: LineField, v: u32) -> bool {
        match self.staged.unwrap_or(self.active).with(f, v) {
            Some(s) => {
                self.staged = Some(s);
                true
            }
            None => false,
        }
    }

    pub(crate) fn revert_staged(&mut self) {
        self.staged = None;
    }

    /// The commit: a staged change becomes due (in force once the answer is sent).
    pub(crate) fn commit(&mut self) {
        if let Some(s) = self.staged.take()
            && s != self.active
        {
            self.change = Change::Due(s);
        }
    }

    /// The answer to the commit was sent (or none is due: a broadcast): a due change
    /// takes effect and waits for its confirmation. Whether one did.
    pub(crate) fn sent(&mut self) -> bool {
        if let Change::Due(s) = self.change {
            self.active = s;
            self.change = Change::Confirming {
                left_ms: u32::from(LINE_CONFIRM_WINDOW_S) * 1000,
            };
            true
        } else {
            false
        }
    }

    /// A valid request reached the node: the master's supervision starts again.
    /// Whether nothing more waits on it (no lost master to report back, no change to
    /// confirm): a poll's case, which then needs no [`request`](Self::request).
    #[inline(always)]
    pub(crate) fn heard(&mut self) -> bool {
        self.silent_ms = 0;
        !self.master_lost && !matches!(self.change, Change::Confirming { .. })
    }

    /// A valid request reached the node (`addressed`: to its unit id, not a
    /// broadcast). Whether this confirmed a change (the kept settings to persist), and
    /// what to raise.
    pub(crate) fn request(&mut self, addressed: bool) -> (bool, Raised) {
        self.silent_ms = 0;
        let confirmed = addressed && matches!(self.change, Change::Confirming { .. });
        if confirmed {
            self.change = Change::None;
            self.kept = self.active;
        }
        let raised = if core::mem::take(&mut self.master_lost) {
            Raised::MasterBack
        } else {
            Raised::Nothing
        };
        (confirmed, raised)
    }

    /// The application's clock (a wrapping ms counter; a step back, or of more than
    /// 2^31 ms, counts as none): the window and the master's supervision run on it.
    pub(crate) fn tick(&mut self, now_ms: u32) -> Raised {
        let dt = match self.last_tick.replace(now_ms) {
            Some(last) if now_ms.wrapping_sub(last) < 1 << 31 => now_ms.wrapping_sub(last),
            _ => 0,
        };
        self.silent_ms = self.silent_ms.saturating_add(dt);
        if let Change::Confirming { left_ms } = self.change {
            let left_ms = left_ms.saturating_sub(dt);
            if left_ms == 0 {
                self.active = self.kept;
                self.change = Change::None;
                self.reverts = self.reverts.wrapping_add(1);
                // The settings before the change: the master had them in hand.
                self.silent_ms = 0;
                return Raised::Reverted;
            }
            self.change = Change::Confirming { left_ms };
        }
        let timeout_ms = u32::from(self.active.bus_timeout_s) * 1000;
        if timeout_ms != 0 && self.silent_ms >= timeout_ms && !self.master_lost {
            self.master_lost = true;
            return Raised::MasterLost;
        }
        Raised::Nothing
    }

    /// The master is lost (no request within the bus timeout).
    pub(crate) fn master_lost(&self) -> bool {
        self.master_lost
    }

    /// Changes undone for want of a confirmation.
    pub(crate) fn reverts(&self) -> u32 {
        self.reverts
    }

    /// Time left (ms) of a change's window; 0 when none waits.
    pub(crate) fn confirm_left_ms(&self) -> u32 {
        match self.change {
            Change::Confirming { left_ms } => left_ms,
            _ => 0,
        }
    }
}
