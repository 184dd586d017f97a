// The node's sensors at the pins: an HX711 on two GPIOs, an ADS1115 on I2C0, a
// tachometer's pulses on a PWM slice's B input and its line monitor. Each takes its
// value from `world` (the trace's row at this emulated time, through the inverse of
// the node's calibration: codes and volts, lab/xtask/src/pico.rs) and can be
// unplugged or stuck. Each conversion adds a dither of up to DITHER codes (as real
// noise would; never the previous code again, so that a steady value is not a stuck
// sensor), except where the drive says the trace held a value bit for bit as long as
// the monitor's stuck time: that sensor then repeats its code, as a frozen one would.

export const DITHER = 4;

/** A deterministic dither (xorshift32) in -DITHER..=DITHER. */
export class Noise {
  constructor(seed) {
    this.state = seed >>> 0 || 1;
  }
  next() {
    let x = this.state;
    x ^= x << 13;
    x >>>= 0;
    x ^= x >>> 17;
    x ^= x << 5;
    x >>>= 0;
    this.state = x;
    return (x % (2 * DITHER + 1)) - DITHER;
  }
}

/** A code from a base code: dithered, never `last` again, clamped to the rails. */
function dithered(base, last, noise, min, max) {
  let code = Math.round(base) + noise.next();
  if (code === last) code += code < max ? 1 : -1;
  return Math.max(min, Math.min(max, code));
}

const HIGH = 1;

/** The HX711 (24-bit, channel A gain 128): DOUT on `dout`, PD_SCK on `sck`. */
export class Hx711 {
  constructor(mcu, sched, world, dout, sck, periodNs) {
    Object.assign(this, { mcu, sched, world, dout, sck, periodNs });
    this.state = 'ok'; // 'ok' | 'unplugged' | 'stuck'
    this.noise = new Noise(0x9e3779b9);
    this.code = 0;
    this.ready = false;
    this.word = 0;
    this.pulses = 0;
    this.poweredDown = false;
    this.highSince = null;
    this.conversions = 0;
    this.setDout(true);
    mcu.gpio[sck].addListener((value) => this.onSck(value === HIGH));
    this.schedule(sched.now() + periodNs);
  }

  setDout(level) {
    this.mcu.gpio[this.dout].setInputValue(this.state === 'unplugged' ? true : level);
  }

  schedule(at) {
    this.next = this.sched.at(at, () => this.convert());
  }

  convert() {
    this.schedule(this.sched.now() + this.periodNs);
    if (this.poweredDown) return;
    const w = this.world.current();
    if (!(this.state === 'stuck' || (w.loadFrozen && this.conversions > 0))) {
      this.code = w.loadBad
        ? 0x7fffff
        : dithered(w.loadCode, this.code, this.noise, -0x800000, 0x7fffff);
    }
    this.conversions += 1;
    this.word = this.code & 0xffffff;
    this.ready = true;
    this.pulses = 0;
    this.setDout(false);
  }

  onSck(high) {
    const now = this.sched.now();
    if (high) {
      this.highSince = now;
      this.sched.at(now + 60e3, () => {
        if (this.highSince === now) {
          this.poweredDown = true;
          this.ready = false;
          this.setDout(true);
        }
      });
      if (!this.ready) return;
      this.pulses += 1;
      if (this.pulses <= 24) {
        this.setDout(!!((this.word >> (24 - this.pulses)) & 1));
      } else {
        // The 25th pulse ends the word: DOUT high until the next conversion.
        this.ready = this.pulses < 25;
        this.setDout(true);
      }
    } else {
      this.highSince = null;
      if (this.poweredDown) {
        this.poweredDown = false;
        this.sched.cancel(this.next);
        this.schedule(now + this.periodNs);
      }
    }
  }

  set(state) {
    this.state = state;
    if (state === 'unplugged') this.setDout(true);
  }
}

/** The ADS1115 at 0x48 on `i2c`: AIN0 probe 1, AIN1 probe 2 (volts from `world`). */
export class Ads1115 {
  constructor(mcu, sched, world, i2c) {
    Object.assign(this, { mcu, sched, world, i2c });
    this.state = 'ok'; // the chip: 'ok' | 'unplugged'
    this.probes = ['ok', 'ok']; // each probe: 'ok' | 'unplugged' | 'stuck'
    this.noise = new Noise(0x85ebca6b);
    this.config = 0x8583;
    this.conversion = 0;
    this.pointer = 0;
    this.busyUntil = 0;
    this.last = [null, null];
    this.written = [];
    this.reading = [];
    this.conversions = 0;
    // rp2040js flushes the TX FIFO on an abort (a NACK) without raising TX_EMPTY,
    // which the data sheet's controller raises at an empty FIFO: embassy-rp's
    // blocking write waits on it for ever.
    const abort = i2c.abort.bind(i2c);
    i2c.abort = (reason) => {
      abort(reason);
      i2c.setInterrupts(1 << 4);
    };
    i2c.onStart = () => i2c.completeStart();
    i2c.onConnect = (address, mode) => {
      const ack = address === 0x48 && this.state === 'ok';
      this.written = [];
      if (ack && mode === 1) {
        const value = this.register(this.pointer);
        this.reading = [value >> 8, value & 0xff];
      }
      i2c.completeConnect(ack);
    };
    i2c.onWriteByte = (byte) => {
      this.write(byte);
      i2c.completeWrite(true);
    };
    i2c.onReadByte = () => i2c.completeRead(this.reading.shift() ?? 0xff);
    i2c.onStop = () => i2c.completeStop();
  }

  register(pointer) {
    if (pointer === 0) return this.conversion & 0xffff;
    if (pointer === 1) {
      const os = this.sched.now() >= this.busyUntil ? 0x8000 : 0;
      return (this.config & 0x7fff) | os;
    }
    return 0;
  }

  /** A byte written: the pointer first, then a register's two bytes (MSB first). */
  write(byte) {
    const w = this.written;
    w.push(byte);
    if (w.length === 1) this.pointer = byte & 3;
    if (w.length === 3 && this.pointer === 1) {
      this.config = (w[1] << 8) | w[2];
      if (this.config & 0x8000) this.start();
    }
  }

  /** A one-shot conversion of the multiplexer's input, done after 1/data rate. */
  start() {
    const mux = (this.config >> 12) & 7;
    const fs = [6.144, 4.096, 2.048, 1.024, 0.512, 0.256, 0.256, 0.256][(this.config >> 9) & 7];
    const rate = [8, 16, 32, 64, 128, 250, 475, 860][(this.config >> 5) & 7];
    const channel = mux - 4; // AIN0..AIN3 against GND
    this.busyUntil = this.sched.now() + 1e9 / rate;
    const w = this.world.current();
    if (channel !== 0 && channel !== 1) {
      this.conversion = 0;
      return;
    }
    const state = this.probes[channel];
    const frozen = w.phiFrozen && this.last[channel] !== null;
    if ((state === 'stuck' || frozen) && this.last[channel] !== null) {
      this.conversion = this.last[channel];
    } else {
      const volts = state === 'unplugged' ? 0 : channel === 0 && w.phiBad ? fs : w.probeVolts[channel];
      const base = (volts / fs) * 32768;
      this.conversion = dithered(base, this.last[channel], this.noise, -32768, 32767);
    }
    this.last[channel] = this.conversion;
    this.conversions += 1;
  }
}

/**
 * The tachometer: rising edges on `pulse` at the world's pulse rate (Hz), and the
 * line monitor on `lineOk` (high: the sensor's line is sound). Unplugged: the line
 * broken (monitor low, no pulses, the input low); stuck: the line shorted (monitor
 * low, the input held high).
 */
export class Tachometer {
  constructor(mcu, sched, world, pulse, lineOk, fixPwm) {
    Object.assign(this, { mcu, sched, world, pulse, lineOk });
    this.state = 'ok';
    this.pulses = 0;
    this.next = null;
    this.phase = 0; // the fraction of a pulse turned since the last edge
    this.rate = 0;
    this.since = sched.now();
    if (fixPwm) fixPwmInput(mcu);
    mcu.gpio[lineOk].setInputValue(true);
    mcu.gpio[pulse].setInputValue(false);
    this.retime();
  }

  /** The pulse rate changed (or the state): the next edge from the phase turned. */
  retime() {
    const now = this.sched.now();
    this.phase += ((now - this.since) / 1e9) * this.rate;
    this.phase -= Math.floor(this.phase);
    this.since = now;
    this.sched.cancel(this.next);
    this.next = null;
    this.rate = this.state === 'ok' ? Math.max(0, this.world.current().pulseHz) : 0;
    if (this.rate > 0) {
      this.next = this.sched.at(now + ((1 - this.phase) / this.rate) * 1e9, () => this.edge());
    }
  }

  edge() {
    const now = this.sched.now();
    const pin = this.mcu.gpio[this.pulse];
    pin.setInputValue(true);
    pin.setInputValue(false);
    this.pulses += 1;
    this.phase = 0;
    this.since = now;
    this.next = this.sched.at(now + 1e9 / this.rate, () => this.edge());
  }

  set(state) {
    this.state = state;
    this.mcu.gpio[this.lineOk].setInputValue(state === 'ok');
    this.mcu.gpio[this.pulse].setInputValue(state === 'stuck');
    this.retime();
  }
}

/**
 * rp2040js 1.4.1 counts no edge on a PWM B input: its check of the pin's direction
 * reads `gpioDirection && 1 << index` (always true once any pin is an output). The
 * datasheet's behaviour: count when the pin is an input of the slice.
 */
function fixPwmInput(mcu) {
  const pwm = mcu.pwm;
  pwm.gpioOnInput = (index) => {
    if (pwm.gpioDirection & (1 << index)) return;
    for (const channel of pwm.channels) {
      if (channel.pinB1 === index || channel.pinB2 === index) channel.gpioBChanged();
    }
  };
}
