//! Requests to answers: functions 1 to 6, 15, 16 and 43/14 over the register map,
//! the checks in the specification's order (function, quantity, address, value),
//! exceptions, broadcasts.

use super::config::{ConfigField, Reg};
use super::div::div_rem;
use super::exception::Exception;
use super::map::{Access, Field, Located, Served, SlotBlock, Table};
use super::rtu::ADU_MAX;
use super::state::Core;
use super::{crc, ident};
use crate::Estimator;
use crate::monitor::annunciation::AlarmSet;

/// Most bits one read returns.
const READ_BITS_MAX: u16 = 2000;
/// Most registers one read returns.
const READ_REGISTERS_MAX: u16 = 125;
/// Most coils one write sets.
const WRITE_BITS_MAX: u16 = 1968;
/// Most registers one write sets.
const WRITE_REGISTERS_MAX: u16 = 123;

/// The big-endian u16 at `i`.
fn be(pdu: &[u8], i: usize) -> Option<u16> {
    let b = pdu.get(i..i + 2)?;
    Some(u16::from_be_bytes([b[0], b[1]]))
}

/// Address and quantity (or value) of a request PDU.
type Head = (u16, u16);

/// The [`Head`] of a request PDU: read once per request (`Core::handle`), not once in
/// each function's handler.
fn head(pdu: &[u8]) -> Result<Head, Exception> {
    match (be(pdu, 1), be(pdu, 3)) {
        (Some(a), Some(q)) => Ok((a, q)),
        _ => Err(Exception::IllegalDataValue),
    }
}

/// Whether `start..start + quantity` lies in `map`.
fn in_map(map: &Served, start: u16, quantity: u16) -> Result<(), Exception> {
    let end = u32::from(start) + u32::from(quantity);
    let (h0, h1) = map.hole;
    // Before the hole (a table without one: `h0` its end) in one test, a poll's case.
    if end <= u32::from(h0) || (start >= h1 && end <= u32::from(map.end)) {
        Ok(())
    } else {
        Err(Exception::IllegalDataAddress)
    }
}

/// The table a read or write function addresses.
const fn table_of(function: u8) -> Table {
    match function {
        1 | 5 | 15 => Table::Coil,
        2 => Table::Discrete,
        4 => Table::Input,
        _ => Table::Holding,
    }
}

/// What a request's handler wrote.
enum Reply {
    /// The PDU from `response[1]`, of this length: the unit and the CRC to add.
    Pdu(usize),
    /// The whole answer, CRC included, of this length.
    Adu(usize),
}

/// The register words of a read being written into the response, high word first:
/// each value whole, from byte `at`, as one slice (one bounds check, not one index per
/// byte). A read writes its data from byte 3
/// to at most byte 252; a value begun before the end runs at most two bytes past it
/// (into the CRC's place, written after), and a read that starts at the low word of a
/// 32-bit value writes that value from byte 1 (the head's place, written after).
struct Words {
    /// A word's width, not a byte's: no narrowing in a read's loop.
    at: usize,
}

impl Words {
    /// Writes the `n`-word value `v` (high word first).
    #[inline(always)]
    fn put(&mut self, response: &mut [u8; ADU_MAX], v: u32, n: u16) {
        let at = self.at;
        // At most byte 251 (see above): always in the buffer.
        if n == 2 {
            if let Some(bytes) = response.get_mut(at..at.wrapping_add(4)) {
                bytes.copy_from_slice(&v.to_be_bytes());
            }
            self.at = at.wrapping_add(4);
        } else {
            if let Some(bytes) = response.get_mut(at..at.wrapping_add(2)) {
                bytes.copy_from_slice(&(v as u16).to_be_bytes());
            }
            self.at = at.wrapping_add(2);
        }
    }
}

impl<E: Estimator> Core<E> {
    /// Answers one frame for this unit or a broadcast (CRC checked by the framer).
    #[inline(never)]
    pub(super) fn handle(&mut self, frame: &[u8]) {
        let (Some(&unit), Some(pdu)) = (frame.first(), frame.get(1..frame.len().saturating_sub(2)))
        else {
            return;
        };
        let Some(&function) = pdu.first() else {
            return;
        };
        self.counters.server_messages = self.counters.server_messages.wrapping_add(1);
        let broadcast = unit == 0;
        let reads = matches!(function, 1..=4 | 43);
        if broadcast && reads {
            // Nothing to apply, nothing to answer.
            return;
        }
        if self.response_len != 0 {
            self.counters.responses_overwritten =
                self.counters.responses_overwritten.wrapping_add(1);
            self.response_len = 0;
            self.held = false;
        }
        // Address and quantity (or value) once, for every function that has them.
        let head = head(pdu);
        // The reads of registers (a master's poll) apart from the dispatch, whose
        // other functions' set-up they then do not share.
        let result = if matches!(function, 3 | 4) {
            head.and_then(|h| self.read_registers(function, h))
                .map(Reply::Adu)
        } else {
            self.dispatch(function, pdu, head).map(Reply::Pdu)
        };
        self.line_request(!broadcast);
        if broadcast {
            // No answer to send: a committed change of the line settings now.
            self.line_sent();
            return;
        }
        let len = match result {
            Ok(Reply::Adu(n)) => {
                self.response_len = n;
                return;
            }
            Ok(Reply::Pdu(n)) => n,
            Err(x) => self.exception(function, x),
        };
        // Store-and-forward: a write is answered once the application has stored
        // what it changed (`Server::stored`).
        self.held = self.events.stored && matches!(function, 5 | 6 | 15 | 16);
        self.seal(len);
    }

    /// The exception `x` to `function` into the response's PDU; its length.
    pub(super) fn exception(&mut self, function: u8, x: Exception) -> usize {
        self.counters.exceptions = self.counters.exceptions.wrapping_add(1);
        if let Some(b) = self.response.get_mut(1..3) {
            b.copy_from_slice(&[function | 0x80, x as u8]);
        }
        2
    }

    /// The unit and the CRC around the response's PDU of `len` bytes: the answer due.
    pub(super) fn seal(&mut self, len: usize) {
        self.response[0] = self.unit;
        // The PDU is at most 253 bytes: the ADU at most 256.
        let end = len.min(253) + 1;
        let crc = crc::crc16(self.response.get(..end).unwrap_or(&[])).to_le_bytes();
        if let Some(tail) = self.response.get_mut(end..end + 2) {
            tail.copy_from_slice(&crc);
            self.response_len = end + 2;
        }
    }

    /// The response PDU into `self.response[1..]`; its length. Every function but the
    /// reads of registers, which [`handle`](Self::handle) answers through
    /// [`read_registers`](Self::read_registers).
    fn dispatch(
        &mut self,
        function: u8,
        pdu: &[u8],
        head: Result<Head, Exception>,
    ) -> Result<usize, Exception> {
        match function {
            1 | 2 => self.read_bits(function, head?),
            5 => self.write_coil(pdu, head?),
            6 => self.write_register(pdu, head?),
            15 => self.write_coils(pdu, head?),
            16 => self.write_registers(pdu, head?),
            43 => {
                let out = self
                    .response
                    .get_mut(1..254)
                    .ok_or(Exception::ServerDeviceFailure)?;
                ident::read(&self.ident, self.model_name, pdu, out)
            }
            _ => Err(Exception::IllegalFunction),
        }
    }

    fn read_bits(&mut self, function: u8, (start, quantity): Head) -> Result<usize, Exception> {
        if quantity == 0 || quantity > READ_BITS_MAX {
            return Err(Exception::IllegalDataValue);
        }
        let map = Served::of(table_of(function));
        in_map(map, start, quantity)?;
        // At most 2000 bits: 250 bytes, from response[3].
        let bytes = usize::from(quantity.div_ceil(8)).min(250);
        self.response[1] = function;
        self.response[2] = bytes as u8;
        if let Some(packed) = self.response.get_mut(3..3 + bytes) {
            packed.fill(0);
        }
        // Inside the map (checked above): one value a bit, packed into the response as
        // it is computed. A bit table is one entry a bit from address 0, without blocks
        // (the map's tests): the bits from `start` are the entries from `start`. Their
        // values are all `value_other`'s (no copy of the registers' inline values).
        let first = usize::from(start);
        let entries = map.entries.get(first..first + usize::from(quantity));
        for (i, e) in (0u16..).zip(entries.unwrap_or(&[])) {
            let on = self.value_other(e.field, 0) & 1 != 0;
            if on && let Some(b) = self.response.get_mut(3 + usize::from(i / 8)) {
                *b |= 1 << (i % 8);
            }
        }
        Ok(2 + bytes)
    }

    /// The whole answer to a read of registers (the unit, the PDU, the CRC); its
    /// length.
    fn read_registers(
        &mut self,
        function: u8,
        (start, quantity): Head,
    ) -> Result<usize, Exception> {
        if quantity == 0 || quantity > READ_REGISTERS_MAX {
            return Err(Exception::IllegalDataValue);
        }
        let map = Served::of(table_of(function));
        in_map(map, start, quantity)?;
        // At most 125 registers: 250 bytes, from response[3].
        let bytes = 2 * quantity.min(125) as u8;
        let end = 3 + bytes;
        // Each table's values from a function of its own (small enough to inline), one
        // `fill` each: a second `fill` with `value_holding` would take it out of line, a
        // call per register. From `LINE_ADDRESS` on (past the reserved run: `in_map`),
        // the line and sensor settings, all `value_other`'s, which `value` falls to.
        if function == 3 && start < super::map::LINE_ADDRESS {
            self.fill::<true>(map, start, usize::from(end), Self::value_holding);
        } else {
            self.fill::<false>(map, start, usize::from(end), Self::value);
        }
        // After the values: the first may have begun in the head's place.
        self.response[..3].copy_from_slice(&[self.unit, function, bytes]);
        let body = self.response.get(..usize::from(end)).unwrap_or(&[]);
        let [lo, hi] = crc::crc16(body).to_le_bytes();
        // At most 253 bytes written: the CRC's two fit.
        self.response[usize::from(end)] = lo;
        self.response[usize::from(end.wrapping_add(1))] = hi;
        Ok(usize::from(end) + 2)
    }

    /// The words of `map` from `start` into the response from byte 3 until byte
    /// `end`, each value computed once by `value` and written whole (see [`Words`]):
    /// inside the map (checked), from the value that holds `start`; the single
    /// entries one after the other, the blocks' records field by field.
    /// `ZERO_BLOCKS`: every word of the blocks reads 0 (the holding blocks are the
    /// external samples, which are written, not read back), written as such.
    #[inline(always)]
    fn fill<const ZERO_BLOCKS: bool>(
        &mut self,
        map: &Served,
        start: u16,
        end: usize,
        value: impl Fn(&Self, Field, u16) -> u32,
    ) {
        // Where the blocks' part starts: the first block's first record when the
        // single entries lead into it.
        let mut from = None;
        let mut out = Words { at: 3 };
        if let Some((i, word)) = map.single(start) {
            // A read from a value's low word: the value from the byte before.
            out.at = 3 - 2 * usize::from(word & 1);
            // The entries by a pointer's steps, not an index's multiplication.
            let mut entries = map.entries.get(i..).unwrap_or(&[]).iter();
            while out.at < end {
                let Some(e) = entries.next() else {
                    from = Some((0, 0, 0));
                    break;
                };
                let v = value(self, e.field, 0);
                out.put(&mut self.response, v, e.words());
            }
        } else if let Some(l) = map.locate(start)
            && let Some(b) = l.block
        {
            out.at = 3 - 2 * usize::from(l.word & 1);
            from = Some((b, l.record, l.index));
        }
        let Some((mut b, mut record, mut i)) = from else {
            return;
        };
        if ZERO_BLOCKS {
            // Inside the map (checked): the words left are the blocks', two at a time
            // (the last pair may run into the CRC's place, as a 32-bit value does).
            while out.at < end {
                out.put(&mut self.response, 0, 2);
            }
            return;
        }
        'blocks: while let Some(block) = map.blocks.get(b) {
            while record < block.count {
                while let Some(e) = block.fields.get(i) {
                    if out.at >= end {
                        break 'blocks;
                    }
                    let v = value(self, e.field, record);
                    out.put(&mut self.response, v, e.words());
                    i += 1;
                }
                (record, i) = (record + 1, 0);
            }
            (b, record) = (b + 1, 0);
        }
    }

    /// Echoes the request's address and value (functions 5 and 6) or address and
    /// quantity (15 and 16).
    fn echo(&mut self, pdu: &[u8]) -> Result<usize, Exception> {
        let src = pdu.get(..5).ok_or(Exception::IllegalDataValue)?;
        let dest = self
            .response
            .get_mut(1..6)
            .ok_or(Exception::ServerDeviceFailure)?;
        dest.copy_from_slice(src);
        Ok(5)
    }

    /// The value at `address` in `map`, if a master may write it.
    fn writable(map: &Served, address: u16) -> Result<Located, Exception> {
        match map.locate(address) {
            Some(l) if l.entry.access == Access::Rw => Ok(l),
            _ => Err(Exception::IllegalDataAddress),
        }
    }

    /// The field of the coil at `address`, if a master may write it: the coils are one
    /// entry a bit from address 0 (the map's tests), found without a search.
    fn writable_coil(address: u16) -> Result<Field, Exception> {
        match Served::of(Table::Coil).entries.get(usize::from(address)) {
            Some(e) if e.access == Access::Rw => Ok(e.field),
            _ => Err(Exception::IllegalDataAddress),
        }
    }

    fn write_coil(&mut self, pdu: &[u8], (address, value): Head) -> Result<usize, Exception> {
        let on = match value {
            0xFF00 => true,
            0x0000 => false,
            _ => return Err(Exception::IllegalDataValue),
        };
        let field = Self::writable_coil(address)?;
        if protected_bit(field) {
            self.commissioning.guard()?;
        }
        self.write_bit(field, on);
        self.echo(pdu)
    }

    fn write_coils(&mut self, pdu: &[u8], (start, quantity): Head) -> Result<usize, Exception> {
        let bytes = usize::from(quantity.div_ceil(8));
        let data = pdu.get(6..).unwrap_or(&[]);
        let declared = pdu.get(5).map_or(0, |&n| usize::from(n));
        if quantity == 0 || quantity > WRITE_BITS_MAX || declared != bytes || data.len() != bytes {
            return Err(Exception::IllegalDataValue);
        }
        let map = Served::of(Table::Coil);
        in_map(map, start, quantity)?;
        let mut protected = false;
        for i in 0..quantity {
            protected |= protected_bit(Self::writable_coil(start.wrapping_add(i))?);
        }
        // One guard for the request: refused whole (and counted once) while locked.
        if protected {
            self.commissioning.guard()?;
        }
        for i in 0..quantity {
            let on = data
                .get(usize::from(i / 8))
                .is_some_and(|b| b >> (i % 8) & 1 != 0);
            let field = Self::writable_coil(start.wrapping_add(i))?;
            self.write_bit(field, on);
        }
        self.echo(pdu)
    }

    fn write_register(&mut self, pdu: &[u8], (address, value): Head) -> Result<usize, Exception> {
        let l = Self::writable(Served::of(Table::Holding), address)?;
        if l.entry.field == Field::Commission(Reg::Scene) {
            let data = pdu.get(3..5).unwrap_or(&[]);
            return self
                .write_scene(address, data)
                .and_then(|()| self.echo(pdu));
        }
        if l.entry.words() != 1 || matches!(l.entry.field, Field::Sample(_)) {
            // Half of a 32-bit value, or part of a sample record.
            return Err(Exception::IllegalDataAddress);
        }
        self.check_word(l.entry.field, u32::from(value), true)?;
        self.write_word(l.entry.field, u32::from(value))?;
        self.echo(pdu)
    }

    fn write_registers(&mut self, pdu: &[u8], (start, quantity): Head) -> Result<usize, Exception> {
        let data = pdu.get(6..).unwrap_or(&[]);
        let declared = pdu.get(5).map_or(0, |&n| usize::from(n));
        let bytes = 2 * usize::from(quantity);
        if quantity == 0
            || quantity > WRITE_REGISTERS_MAX
            || declared != bytes
            || data.len() != bytes
        {
            return Err(Exception::IllegalDataValue);
        }
        let map = Served::of(Table::Holding);
        in_map(map, start, quantity)?;
        let word = |i: u16| be(data, 2 * usize::from(i)).unwrap_or(0);
        if start >= map.entries_end && start < super::map::LINE_ADDRESS {
            let block = map
                .blocks
                .iter()
                .find(|b| start < b.end())
                .ok_or(Exception::IllegalDataAddress)?;
            if start >= super::map::SCENE_ADDRESS {
                return self.write_scene(start, data).and_then(|()| self.echo(pdu));
            }
            return self
                .write_samples(block, start, quantity, data)
                .and_then(|()| self.echo(pdu));
        }
        // Single entries only, each whole and writable: checked, then written.
        // Inside the map (checked above): no u16 below wraps.
        let end = start.wrapping_add(quantity);
        if start < map.entries_end && end > map.entries_end {
            return Err(Exception::IllegalDataAddress);
        }
        for pass in [false, true] {
            let mut a = start;
            while a < end {
                let l = Self::writable(map, a)?;
                let n = l.entry.words();
                if l.word != 0 || a.wrapping_add(n) > end {
                    return Err(Exception::IllegalDataAddress);
                }
                let i = a.wrapping_sub(start);
                let v = if n == 2 {
                    u32::from(word(i)) << 16 | u32::from(word(i.wrapping_add(1)))
                } else {
                    u32::from(word(i))
                };
                if pass {
                    self.write_word(l.entry.field, v)?;
                } else {
                    self.check_word(l.entry.field, v, quantity == 1)?;
                }
                a = a.wrapping_add(n);
            }
        }
        self.echo(pdu)
    }

    /// Whole records of external samples into `block`: checked, then processed in
    /// order. A refused write processes none and is counted.
    fn write_samples(
        &mut self,
        block: &SlotBlock,
        start: u16,
        quantity: u16,
        data: &[u8],
    ) -> Result<(), Exception> {
        let result = self.check_samples(block, start, quantity, data);
        if result.is_err() {
            self.counters.external_refused = self.counters.external_refused.wrapping_add(1);
        }
        let records = result?;
        for record in Self::records(block, data, records) {
            if let Some(sample) = super::values::sample_from_record(block, record) {
                self.counters.external_accepted = self.counters.external_accepted.wrapping_add(1);
                self.process(sample);
            }
        }
        Ok(())
    }

    /// The first `records` whole records of `block` in `data` (without a division:
    /// `chunks_exact` would link one into a Cortex-M0 node).
    fn records<'a>(
        block: &SlotBlock,
        data: &'a [u8],
        records: u16,
    ) -> impl Iterator<Item = &'a [u8]> {
        let n = 2 * usize::from(block.stride);
        (0..usize::from(records)).map_while(move |k| {
            let at = k.checked_mul(n)?;
            data.get(at..at.checked_add(n)?)
        })
    }

    /// The number of whole records of a write to `block`, or why it is refused.
    fn check_samples(
        &self,
        block: &SlotBlock,
        start: u16,
        quantity: u16,
        data: &[u8],
    ) -> Result<u16, Exception> {
        let offset = start
            .checked_sub(block.address)
            .ok_or(Exception::IllegalDataAddress)?;
        let stride = block.stride;
        let split = |n| div_rem(n, stride).unwrap_or((0, 1));
        let ((_, first), (records, rest)) = (split(offset), split(quantity));
        let whole = first == 0 && rest == 0;
        if !whole || u32::from(start) + u32::from(quantity) > u32::from(block.end()) {
            return Err(Exception::IllegalDataAddress);
        }
        if !self.external {
            return Err(Exception::IllegalFunction);
        }
        for record in Self::records(block, data, records) {
            if super::values::sample_from_record(block, record).is_none() {
                return Err(Exception::IllegalDataValue);
            }
        }
        Ok(records)
    }

    /// Whether `v` is in the domain of the writable register `field`, and a
    /// commissioning write is unlocked (`alone`: the request writes this register
    /// only, as `unlock` and `command` must be written).
    fn check_word(&mut self, field: Field, v: u32, alone: bool) -> Result<(), Exception> {
        let ok = match field {
            Field::AcknowledgeAlarms => v <= 15,
            // Configuration of the alarms and of the sample source: the unlock's.
            Field::LatchingAlarms => {
                self.commissioning.guard()?;
                v <= 15
            }
            Field::ExternalMode => {
                self.commissioning.guard()?;
                v <= 1
            }
            Field::EventFrom => true,
            // Only numbers already given: a later one would acknowledge an event not
            // yet raised.
            Field::EventAck => self.events.given(v, self.monitor.next_event_seq()),
            Field::Commission(Reg::Unlock | Reg::Command) if !alone => {
                return Err(Exception::IllegalDataAddress);
            }
            Field::Commission(Reg::Unlock) => true,
            Field::LineStaged(f) => {
                self.commissioning.guard()?;
                f.takes(v)
            }
            Field::SensorStaged(f) => {
                self.commissioning.guard()?;
                f.takes(v)
            }
            Field::Commission(Reg::Command | Reg::NewCode) | Field::Staged(_) => {
                self.commissioning.guard()?;
                !matches!(
                    field,
                    Field::Staged(ConfigField::ThresholdsOn | ConfigField::Friction)
                ) || v <= 1
            }
            _ => false,
        };
        if ok {
            Ok(())
        } else {
            Err(Exception::IllegalDataValue)
        }
    }

    fn write_bit(&mut self, field: Field, on: bool) {
        // Guarded by the caller (`protected_bit`).
        let latching = self.annunciator.latching();
        match field {
            Field::Acknowledge if on => self.annunciator.acknowledge(AlarmSet::ALL),
            Field::Latching(which) => self.switch(latching.with(which, on), self.external),
            Field::ExternalSamples => self.switch(latching, on),
            _ => {}
        }
    }

    /// Latching and the samples' source set (the guard passed); a change is kept as a
    /// commit is (`Server::take_committed`), a write of the same values stores nothing.
    fn switch(&mut self, latching: AlarmSet, external: bool) {
        if (latching, external) != (self.annunciator.latching(), self.external) {
            self.annunciator.set_latching(latching);
            self.external = external;
            self.commissioning.switched();
        }
    }

    fn write_word(&mut self, field: Field, v: u32) -> Result<(), Exception> {
        let bits = AlarmSet::from_bits(v as u8);
        let c = &mut self.commissioning;
        match field {
            Field::EventFrom => self.events.from = v,
            Field::EventAck => {
                self.ack = Some(v);
                self.events.acknowledge(v, self.monitor.next_event_seq());
            }
            Field::AcknowledgeAlarms => self.annunciator.acknowledge(bits),
            Field::LatchingAlarms => self.switch(bits, self.external),
            Field::ExternalMode => self.switch(self.annunciator.latching(), v != 0),
            Field::Staged(f) => c.write_staged(f, v, self.monitor.config()),
            Field::LineStaged(f) => c.write_line(&mut self.line, f, v),
            Field::SensorStaged(f) => c.write_sensor(&mut self.sensing, f, v),
            Field::Commission(Reg::NewCode) => c.write_new_code(v as u16),
            Field::Commission(Reg::Unlock) => c.unlock(v as u16)?,
            Field::Commission(Reg::Command) => {
                c.command(
                    v as u16,
                    &mut self.monitor,
                    &mut self.line,
                    &mut self.sensing,
                )?;
                // The events lost count with the statistics (`events_dropped`): the
                // window's share starts afresh with the monitor's.
                if v == u32::from(super::config::command::RESET_STATISTICS) {
                    self.events.dropped = 0;
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// Registers written into the scene block from `start` (big-endian words, the
    /// prepared scene's bytes in order).
    fn write_scene(&mut self, start: u16, data: &[u8]) -> Result<(), Exception> {
        let at = start
            .checked_sub(super::map::SCENE_ADDRESS)
            .ok_or(Exception::IllegalDataAddress)?;
        self.commissioning.write_scene(2 * usize::from(at), data)
    }
}

/// Whether writing the coil `field` changes configuration (which alarms latch, where
/// samples come from), and so needs the unlock; acknowledging does not.
fn protected_bit(field: Field) -> bool {
    matches!(field, Field::Latching(_) | Field::ExternalSamples)
}

#[cfg(test)]
mod tests {
    use super::super::{Server, ServerConfig};
    use super::*;
    use crate::monitor::{Config, Monitor, Sample, model_for_range};
    use crate::{Scene, float::Auto};
    use std::vec::Vec;

    /// A server over the demo scene's f32 core and the default monitor.
    fn server(config: ServerConfig) -> Server<Auto> {
        let scene = Scene::DEMO;
        let core = Auto::with_choice(&scene, model_for_range(&scene, 5e3, 1e-5).unwrap()).unwrap();
        let monitor = Monitor::new(core, Config::default()).unwrap();
        Server::new(monitor, config).unwrap()
    }

    /// Every read of bits (functions 1 and 2), from every address and of every length
    /// the table holds, answers each bit as its entry's value, with the head and the
    /// CRC of a valid frame; one past the table is exception 02.
    #[test]
    fn every_read_of_bits_is_each_bits_value() {
        let config = ServerConfig {
            external_samples: true,
            latching: super::AlarmSet::ALARM,
            ..ServerConfig::default()
        };
        let mut server = server(config);
        for i in 0..200u32 {
            let load = 2e3 + 40.0 * i as f32;
            server.process(Sample::new(i * 1000, load, 1e-4 * (i % 7) as f32).with_speed(2.0));
        }
        for function in [1u8, 2] {
            let map = Served::of(table_of(function));
            let bits: Vec<u8> = (0..map.end)
                .map(|a| {
                    let l = map.locate(a).unwrap();
                    (server.core.value_other(l.entry.field, l.record) & 1) as u8
                })
                .collect();
            assert!(bits.contains(&1), "{function}: some bit set");
            for start in 0..map.end {
                for quantity in 1..=map.end - start {
                    let [a, b] = start.to_be_bytes();
                    let [c, d] = quantity.to_be_bytes();
                    let pdu = [function, a, b, c, d];
                    let n = server.core.dispatch(function, &pdu, head(&pdu)).unwrap();
                    let bytes = usize::from(quantity.div_ceil(8));
                    assert_eq!(n, bytes + 2);
                    assert_eq!(server.core.response[1..3], [function, bytes as u8]);
                    for i in 0..usize::from(quantity) {
                        let bit = server.core.response[3 + i / 8] >> (i % 8) & 1;
                        let s = usize::from(start);
                        assert_eq!(bit, bits[s + i], "{function} {start}+{quantity}: bit {i}");
                    }
                }
                let [a, b] = start.to_be_bytes();
                let [c, d] = (map.end - start + 1).to_be_bytes();
                let pdu = [function, a, b, c, d];
                let past = server.core.dispatch(function, &pdu, head(&pdu));
                assert_eq!(past, Err(Exception::IllegalDataAddress));
            }
        }
    }

    /// Every write of coils (function 15) from every address and of every length sets
    /// those coils and no other, as a read of coils then shows (the coil
    /// `acknowledge` reads 0); function 5 likewise one at a time; past the table, 02.
    #[test]
    fn every_write_of_coils_sets_those_coils() {
        let mut server = server(ServerConfig::default());
        // The latching and sample-source coils need the unlock (the site's code).
        let code = crate::modbus::config::DEFAULT_UNLOCK_CODE.to_be_bytes();
        let unlock = [6, 0, 9, code[0], code[1]];
        server.core.dispatch(6, &unlock, head(&unlock)).unwrap();
        let coils = |server: &mut Server<Auto>| {
            let pdu = [1, 0, 0, 0, 6];
            server.core.dispatch(1, &pdu, head(&pdu)).unwrap();
            server.core.response[3]
        };
        let end = Served::of(Table::Coil).end;
        assert_eq!(end, 6);
        for pattern in [0u8, 0x3F, 0x15, 0x2A] {
            for start in 0..end {
                for quantity in 1..=end - start {
                    let before = coils(&mut server);
                    let bits = pattern >> start;
                    let pdu = [15, 0, start as u8, 0, quantity as u8, 1, bits];
                    let n = server.core.dispatch(15, &pdu, head(&pdu)).unwrap();
                    assert_eq!(server.core.response[1..=n], pdu[..5]);
                    let mask = ((1u8 << quantity) - 1) << start;
                    let expected = (before & !mask | pattern & mask) & !1;
                    assert_eq!(coils(&mut server), expected, "{pattern} {start}+{quantity}");
                }
                let on = if pattern >> start & 1 != 0 { 0xFF } else { 0 };
                let pdu = [5, 0, start as u8, on, 0];
                server.core.dispatch(5, &pdu, head(&pdu)).unwrap();
                let bit = coils(&mut server) >> start & 1;
                assert_eq!(bit, pattern >> start & 1 & u8::from(start != 0), "{start}");
            }
            let pdu = [15, 0, 5, 0, 2, 1, 3];
            let past = server.core.dispatch(15, &pdu, head(&pdu));
            assert_eq!(past, Err(Exception::IllegalDataAddress));
            let pdu = [5, 0, 6, 0xFF, 0];
            let past = server.core.dispatch(5, &pdu, head(&pdu));
            assert_eq!(past, Err(Exception::IllegalDataAddress));
        }
    }

    /// Every read of registers, from every address and of every length the table
    /// allows (up to 125), answers each register as the value that holds it, located
    /// alone and computed alone, with the head and the CRC of a valid frame; a read
    /// that touches the reserved addresses is refused.
    #[test]
    fn every_read_of_registers_is_each_registers_value() {
        let mut server = server(ServerConfig::default());
        for i in 0..200u32 {
            let load = 2e3 + 10.0 * i as f32;
            server.process(Sample::new(i * 1000, load, 1e-4 * (i % 7) as f32).with_speed(2.0));
        }
        for function in [3u8, 4] {
            let map = Served::of(table_of(function));
            let reserved = map.hole.0..map.hole.1;
            let expected: Vec<u16> = (0..map.end)
                .map(|a| {
                    let Some(l) = map.locate(a) else {
                        assert!(reserved.contains(&a), "{a}");
                        return 0;
                    };
                    let (field, record) = (l.entry.field, l.record);
                    let other = server.core.value_other(field, record);
                    // The commissioning registers are value_holding's alone; every
                    // other value reads the same inline and out of line.
                    let v = match field {
                        Field::Commission(_) | Field::Staged(_) => {
                            server.core.value_holding(field, record)
                        }
                        _ => other,
                    };
                    let low = l.entry.words() == 1 || l.word == 1;
                    (if low { v } else { v >> 16 }) as u16
                })
                .collect();
            for start in 0..map.end {
                for quantity in 1..=(map.end - start).min(READ_REGISTERS_MAX) {
                    let [a, b] = start.to_be_bytes();
                    let [c, d] = quantity.to_be_bytes();
                    let read = server
                        .core
                        .read_registers(function, head(&[function, a, b, c, d]).unwrap());
                    if start < reserved.end && start + quantity > reserved.start {
                        assert_eq!(read, Err(Exception::IllegalDataAddress));
                        continue;
                    }
                    let n = read.unwrap();
                    let answer = &server.core.response[..n];
                    let bytes = 2 * usize::from(quantity);
                    assert_eq!(n, bytes + 5);
                    assert_eq!(answer[..3], [1, function, bytes as u8]);
                    assert!(crc::valid(answer), "{function} {start}+{quantity}");
                    let words: Vec<u16> = answer[3..3 + bytes]
                        .chunks(2)
                        .map(|w| u16::from_be_bytes([w[0], w[1]]))
                        .collect();
                    let s = usize::from(start);
                    assert_eq!(
                        words,
                        expected[s..s + usize::from(quantity)],
                        "{function} {start}+{quantity}"
                    );
                }
            }
        }
    }
}
