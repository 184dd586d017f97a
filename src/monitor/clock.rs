//! The clock stage: the node's free-running u32 millisecond counter made monotonic
//! (a wrap is a forward step, a jump back is a reset).

/// How a timestamp relates to the previous one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Step {
    /// The first sample since start or restore.
    First,
    /// Forward by this many ms (across a wrap too).
    Forward(u32),
    /// The same timestamp again.
    Repeated,
    /// Backwards: the counter jumped back (a reset), not a wrap.
    Backwards,
}

/// The clock: last raw timestamp and the monotonic time since the monitor started.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Clock {
    /// The last accepted raw timestamp (ms), `None` before the first sample.
    pub(crate) last_time_ms: Option<u32>,
    /// Monotonic time since the first sample (ms), the sum of forward steps.
    pub(crate) elapsed_ms: u64,
}

impl Clock {
    /// The clock before the first sample.
    pub(crate) const fn new() -> Self {
        Clock {
            last_time_ms: None,
            elapsed_ms: 0,
        }
    }

    /// Steps the clock to `time_ms`. A u32 counter difference below 2^31 ms (24.8
    /// days) is a forward step, across a wrap too; a larger one is the counter going
    /// backwards. A backwards step re-anchors the clock at the new timestamp (after a
    /// counter reset the following samples go forward again) and adds no time.
    pub(crate) fn step(&mut self, time_ms: u32) -> Step {
        let step = match self.last_time_ms {
            None => Step::First,
            Some(last) => match time_ms.wrapping_sub(last) {
                0 => Step::Repeated,
                d if d < 1 << 31 => Step::Forward(d),
                _ => Step::Backwards,
            },
        };
        if let Step::Forward(d) = step {
            // Forward steps below 2^31 ms: u64 cannot wrap in 500 000 years.
            self.elapsed_ms = self.elapsed_ms.wrapping_add(u64::from(d));
        }
        if step != Step::Repeated {
            self.last_time_ms = Some(time_ms);
        }
        step
    }
}
