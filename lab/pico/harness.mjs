// The Pico node in rp2040js (cargo xtask pico runs it; README.md beside this file):
//
//   node harness.mjs --elf NODE.elf --flash FLASH.bin --port PORT --drive DRIVE.csv
//       [--control PORT] [--realtime] [--defmt-print PATH] [--samples OUT] [--parent PID]
//
// Boots the node's ELF at its vector table with no ROM binary (src/rom.mjs), its flash
// a file the harness owns (src/flash.mjs), UART0 as the PL011 behaves (src/uart.mjs)
// bridged to 127.0.0.1:PORT for any Modbus RTU master (the driver-enable pin GP2
// checked against the transmitter), its sensors at the pins (src/sensors.mjs) driven
// by DRIVE.csv (the trace's rows as codes and volts, written by xtask), emulated time
// skipped while the core sleeps (or paced to the wall clock with --realtime). The
// node's defmt log (RTT, read from its RAM) is decoded by defmt-print onto stdout; its
// `sample` lines go to --samples. A control port takes one command a line (answering
// one JSON line): status, sensor NAME ok|unplugged|stuck, cut N POINTS, reset,
// drive PATH (new rows before the trace starts), quit.
import fs from 'node:fs';
import net from 'node:net';
import { spawn } from 'node:child_process';
import { RP2040, ConsoleLogger, LogLevel } from 'rp2040js';
import { readElf } from './src/elf.mjs';
import { installRom, romHandler } from './src/rom.mjs';
import { FlashImage } from './src/flash.mjs';
import { Uart } from './src/uart.mjs';
import { Hx711, Ads1115, Tachometer } from './src/sensors.mjs';

const CYCLE_NS = 8; // 125 MHz, as embassy-rp sets the system clock
const VTOR = 0x10000100; // the vector table, after the 256-byte second-stage loader
const PINS = { de: 2, lineOk: 6, pulse: 7, dout: 10, sck: 11 };
const HX711_PERIOD_NS = 12.5e6; // 80 samples a second (RATE high)
const PAINT = 0xcccccccc;

function args() {
  const a = { realtime: false };
  const argv = process.argv.slice(2);
  for (let i = 0; i < argv.length; i++) {
    const k = argv[i].replace(/^--/, '');
    if (k === 'realtime') a.realtime = true;
    else a[k] = argv[++i];
  }
  for (const k of ['elf', 'flash', 'port', 'drive']) {
    if (!a[k]) throw new Error(`--${k} is required`);
  }
  return a;
}

const say = (m) => process.stderr.write(`pico-harness: ${m}\n`);

/** Events at emulated times (ns since the harness started), over the boots' clocks. */
class Scheduler {
  constructor() {
    this.events = [];
    this.epoch = 0;
    this.clock = null;
    this.alarm = null;
    this.ids = 0;
  }
  attach(clock) {
    if (this.clock) this.epoch += this.clock.nanos;
    this.clock = clock;
    this.alarm = clock.createAlarm(() => this.fire());
    this.rearm();
  }
  now() {
    return this.epoch + this.clock.nanos;
  }
  at(t, fn) {
    const e = { t, fn, id: ++this.ids };
    let i = this.events.length;
    while (i > 0 && this.events[i - 1].t > t) i--;
    this.events.splice(i, 0, e);
    if (i === 0) this.rearm();
    return e;
  }
  cancel(e) {
    if (!e) return;
    const i = this.events.indexOf(e);
    if (i >= 0) {
      this.events.splice(i, 1);
      if (i === 0) this.rearm();
    }
  }
  clear() {
    this.events = [];
    this.rearm();
  }
  rearm() {
    if (!this.alarm) return;
    this.alarm.cancel();
    if (this.events.length) this.alarm.schedule(Math.max(0, this.events[0].t - this.now()));
  }
  fire() {
    while (this.events.length && this.events[0].t <= this.now()) {
      this.events.shift().fn();
    }
    this.rearm();
  }
}

/** The trace's rows (DRIVE.csv) at emulated times: row 0 until the anchor. */
class World {
  constructor(path, sched, periodNs) {
    this.load(path);
    this.sched = sched;
    this.periodNs = periodNs;
    this.i = 0;
    this.anchorNs = null;
    this.anchorMs = null;
    this.listeners = [];
    this.next = null;
  }
  /** DRIVE.csv's rows (again, before the trace starts: `drive PATH`). */
  load(path) {
    const lines = fs.readFileSync(path, 'utf8').trim().split('\n');
    const header = lines[0].split(',');
    const col = (n) => header.indexOf(n);
    this.rows = lines.slice(1).map((l) => {
      const c = l.split(',');
      const flags = Number(c[col('flags')]);
      return {
        tMs: Number(c[col('t_ms')]),
        loadCode: Number(c[col('load_code')]),
        probeVolts: [Number(c[col('probe1_v')]), Number(c[col('probe2_v')])],
        pulseHz: Number(c[col('pulse_hz')]),
        loadFrozen: !!(flags & 1),
        phiFrozen: !!(flags & 2),
        loadBad: !!(flags & 4),
        phiBad: !!(flags & 8),
      };
    });
  }
  current() {
    return this.rows[this.i];
  }
  startNs(i) {
    return this.anchorNs + (this.rows[i].tMs - this.rows[0].tMs) * 1e6 - this.periodNs / 2;
  }
  /** The first monitored sample at the node's `ms` (this boot): row 0 is its row. */
  anchor(ms, bootEpochNs) {
    if (this.anchorNs !== null) return;
    this.anchorMs = ms;
    this.anchorNs = bootEpochNs + ms * 1e6;
    this.rearm();
  }
  rearm() {
    this.sched.cancel(this.next);
    this.next = null;
    if (this.anchorNs === null || this.i + 1 >= this.rows.length) return;
    this.next = this.sched.at(Math.max(this.sched.now(), this.startNs(this.i + 1)), () => {
      this.i += 1;
      for (const f of this.listeners) f();
      this.rearm();
    });
  }
  /** Whether the trace has played: its last row held for a period. */
  done() {
    return this.anchorNs !== null && this.i + 1 >= this.rows.length &&
      this.sched.now() >= this.startNs(this.rows.length - 1) + this.periodNs;
  }
  endMs() {
    return this.anchorMs === null ? null : this.anchorMs + this.rows.at(-1).tMs - this.rows[0].tMs;
  }
}

class Harness {
  constructor(a) {
    this.a = a;
    const elfBytes = fs.readFileSync(a.elf);
    this.elf = readElf(elfBytes);
    this.flash = new FlashImage(a.flash);
    this.flash.load(this.elf.segments);
    this.sched = new Scheduler();
    this.world = new World(a.drive, this.sched, 100e6);
    this.boots = 0;
    this.deErrors = 0;
    this.de = false;
    this.txOn = false;
    this.samples = 0;
    this.sockets = new Set();
    this.rxQueue = [];
    this.states = { load: 'ok', probe1: 'ok', probe2: 'ok', ads: 'ok', tach: 'ok' };
    this.cutPending = false;
    this.flash.onCut = () => {
      this.cutPending = true;
    };
    this.flash.onBusy = (ns) => this.clock.tick(ns);
    this.samplesOut = a.samples ? fs.openSync(a.samples, 'w') : null;
    this.startDecoder();
    this.boot();
  }

  startDecoder() {
    const tool = this.a['defmt-print'] || 'defmt-print';
    this.decoder = spawn(tool, ['-e', this.a.elf, 'stdin'], { stdio: ['pipe', 'pipe', 'inherit'] });
    this.decoder.on('error', (e) => say(`defmt-print: ${e.message}`));
    let rest = '';
    this.decoder.stdout.on('data', (chunk) => {
      rest += chunk.toString();
      const lines = rest.split('\n');
      rest = lines.pop();
      for (const line of lines) this.logLine(line);
    });
  }

  logLine(line) {
    // The sampling period the node runs: the trace's rows change half of one before
    // their time.
    const period = line.match(/sensors: sample period (\d+) ms/);
    if (period) this.world.periodNs = Number(period[1]) * 1e6;
    const m = line.match(/sample t=(\d+) P=(\d+) phi=(\d+) measured=(true|false) V=(\d+) fault=(\d+)/);
    if (m) {
      this.samples += 1;
      if (this.samplesOut !== null) fs.writeSync(this.samplesOut, `${m.slice(1).join(',')}\n`);
      return;
    }
    process.stdout.write(`${line}\n`);
  }

  /** Power on (again): a new chip and clock over the same flash image. */
  boot() {
    this.boots += 1;
    const mcu = new RP2040();
    const clock = mcu.clock;
    mcu.logger = new ConsoleLogger(LogLevel.Error, true);
    this.clock = clock;
    this.mcu = mcu;
    this.sched.clear();
    this.sched.attach(clock);
    this.bootEpoch = this.sched.now();
    mcu.flash.set(this.flash.bytes);
    // Writes to flash through XIP are not flash: the ROM's routines are the only way.
    installRom(mcu);
    mcu.onBreak = romHandler(mcu, this.flash, say);
    // XIP_CTRL (0x14000000), which rp2040js leaves out (its reads answer 0xffffffff:
    // embassy-rp's flash driver waits on STREAM_CTR for ever): no cache to flush, no
    // stream running, the stream FIFO empty.
    mcu.peripherals[0x14000] = {
      readUint32: (offset) => (offset === 0x08 ? 0b011 : 0),
      writeUint32Atomic: () => {},
    };
    // The pads' reset value (datasheet 2.19.6.3: 0x56, input enabled, pull-down,
    // Schmitt trigger); rp2040js starts them at 0x36, input disabled, so that a pin
    // the firmware does not configure as a GPIO input (the PWM slice's B input) reads
    // nothing.
    for (const pin of mcu.gpio) pin.padValue = 0x56;
    // The stack painted (cortex-m-rt's stack region, `_stack_end` up to
    // `_stack_start`): `status` reports the deepest stack the node used since.
    const paint = this.stackBounds();
    if (paint) {
      for (let a = paint.bottom; a < paint.top; a += 4) mcu.writeUint32(a, PAINT);
    }
    mcu.core.VTOR = VTOR;
    mcu.core.reset();
    // The flash the ROM changes, seen through XIP at once (the harness's image is the
    // chip's).
    mcu.flash = this.flash.bytes;
    mcu.flashView = new DataView(this.flash.bytes.buffer);
    mcu.flash16 = new Uint16Array(this.flash.bytes.buffer);
    const wd = mcu.peripherals[0x40058];
    wd.onWatchdogTrigger = () => {
      say(`the watchdog restarted the node (pc ${mcu.core.PC.toString(16)})`);
      this.resetPending = true;
    };
    this.uart = new Uart(mcu, mcu.uart[0], this.sched, (b) => this.toMaster(b), (on) => this.transmitting(on));
    mcu.gpio[PINS.de].addListener((v) => {
      this.de = v === 1;
    });
    this.de = false;
    this.hx711 = new Hx711(mcu, this.sched, this.world, PINS.dout, PINS.sck, HX711_PERIOD_NS);
    this.ads = new Ads1115(mcu, this.sched, this.world, mcu.i2c[0]);
    this.tach = new Tachometer(mcu, this.sched, this.world, PINS.pulse, PINS.lineOk, true);
    this.world.listeners = [() => this.tach.retime()];
    this.world.rearm();
    this.applyStates();
    const rtt = this.elf.symbols.get('_SEGGER_RTT');
    this.rtt = rtt ?? null;
    const poll = () => {
      this.readRtt();
      this.sched.at(this.sched.now() + 1e6, poll);
    };
    poll();
  }

  stackBounds() {
    const top = this.elf.symbols.get('_stack_start');
    const bottom = this.elf.symbols.get('_stack_end');
    return top && bottom && bottom < top ? { top, bottom } : null;
  }

  /** The deepest stack the node used since its boot (bytes). */
  stackUsed() {
    const b = this.stackBounds();
    if (!b) return null;
    let a = b.bottom;
    while (a < b.top && this.mcu.readUint32(a) === PAINT) a += 4;
    return b.top - a;
  }

  applyStates() {
    this.hx711.set(this.states.load);
    this.ads.state = this.states.ads;
    this.ads.probes = [this.states.probe1, this.states.probe2];
    this.tach.set(this.states.tach);
  }

  readRtt() {
    if (this.rtt === null) return;
    const m = this.mcu;
    const up = this.rtt + 24;
    const buf = m.readUint32(up + 4);
    const size = m.readUint32(up + 8);
    const wr = m.readUint32(up + 12);
    let rd = m.readUint32(up + 16);
    if (!size || wr >= size || rd >= size || wr === rd) return;
    const out = [];
    while (rd !== wr) {
      out.push(m.readUint8(buf + rd));
      rd = (rd + 1) % size;
    }
    m.writeUint32(up + 16, rd);
    this.decoder.stdin.write(Buffer.from(out));
    // The first monitored sample anchors the trace.
  }

  toMaster(byte) {
    if (!this.de) this.deErrors += 1;
    for (const s of this.sockets) s.write(Buffer.from([byte]));
  }

  transmitting(on) {
    this.txOn = on;
    if (on && !this.de) {
      this.deErrors += 1;
      say('driver enable low as the node starts a byte');
    }
    if (!on) {
      // The driver must be off within a character time after the last stop bit, or
      // it holds the bus against the master's next request.
      const at = this.sched.now();
      this.sched.at(at + this.uart.charNs(), () => {
        if (this.de && !this.txOn) {
          this.deErrors += 1;
          say('driver enable still high a character after the answer');
        }
      });
    }
  }

  fromMaster(data) {
    if (this.de) {
      this.deErrors += 1;
      say('a master sends while the node drives the line');
    }
    for (const b of data) this.uart.receive(b);
    this.wake?.();
  }

  /** Runs the core; returns when it is time to let I/O in. */
  run() {
    const { a } = this;
    const start = performance.now();
    while (performance.now() - start < 25) {
      for (let i = 0; i < 5000; i++) {
        const core = this.mcu.core;
        if (core.waiting) {
          const dt = this.clock.nanosToNextAlarm;
          if (dt <= 0) break;
          if (a.realtime) {
            const ahead = this.sched.now() + dt - this.wallNs();
            if (ahead > 0) return Math.min(ahead / 1e6, 50);
          }
          this.clock.tick(dt);
        } else {
          this.clock.tick(core.executeInstruction() * CYCLE_NS);
        }
        if (this.cutPending || this.resetPending) {
          say(this.cutPending ? 'power cut' : 'reset');
          this.cutPending = false;
          this.resetPending = false;
          this.readRtt();
          this.boot();
        }
      }
      if (a.realtime && this.sched.now() - this.wallNs() > 20e6) return 5;
    }
    return 0;
  }

  wallNs() {
    return (performance.now() - this.wallStart) * 1e6;
  }

  loop() {
    this.wallStart = performance.now();
    const step = () => {
      this.timer = null;
      const wait = this.run();
      if (wait > 0) this.timer = setTimeout(step, wait);
      else setImmediate(step);
    };
    // A master's bytes end a wait at once (paced to the wall clock, the core may be
    // asleep until its next sample).
    this.wake = () => {
      if (this.timer) {
        clearTimeout(this.timer);
        this.timer = null;
        setImmediate(step);
      }
    };
    step();
  }

  status() {
    return {
      ns: this.sched.now(),
      pc: this.mcu.core.PC,
      waiting: this.mcu.core.waiting,
      boots: this.boots,
      samples: this.samples,
      flash_ops: this.flash.ops,
      de_errors: this.deErrors,
      overruns: this.uart.overruns,
      uart_read: this.uart.received,
      anchored: this.world.anchorNs !== null,
      done: this.world.done(),
      end_ms: this.world.endMs(),
      hx711_conversions: this.hx711.conversions,
      ads1115_conversions: this.ads.conversions,
      pulses: this.tach.pulses,
      stack: this.stackUsed(),
      stack_reserved: this.stackBounds() ? this.stackBounds().top - this.stackBounds().bottom : null,
    };
  }

  control(line) {
    const w = line.trim().split(/\s+/);
    switch (w[0]) {
      case 'status':
        return this.status();
      case 'sensor':
        if (!(w[1] in this.states) || !['ok', 'unplugged', 'stuck'].includes(w[2])) {
          return { error: `sensor ${w[1]} ${w[2]}` };
        }
        this.states[w[1]] = w[2];
        this.applyStates();
        return { ok: true };
      case 'cut':
        this.flash.arm(Number(w[1]), Number(w[2] ?? 0));
        return { ok: true, ops: this.flash.ops };
      case 'reset':
        this.resetPending = true;
        return { ok: true };
      case 'drive':
        // New rows for the sensors (the inverse of the calibration the node runs),
        // before the trace starts.
        if (this.world.anchorNs !== null) return { error: 'the trace has started' };
        try {
          this.world.load(w[1]);
        } catch (e) {
          return { error: `drive ${w[1]}: ${e.message}` };
        }
        this.world.i = 0;
        for (const f of this.world.listeners) f();
        return { ok: true, rows: this.world.rows.length };
      case 'quit':
        setTimeout(() => process.exit(0), 10);
        return { ok: true };
    }
    return { error: `unknown command ${w[0]}` };
  }
}

const a = args();
const h = new Harness(a);
// The first monitored sample anchors the trace (the sample lines carry its time).
const logLine = h.logLine.bind(h);
h.logLine = (line) => {
  const m = line.match(/sample t=(\d+)/);
  if (m) h.world.anchor(Number(m[1]), h.bootEpoch);
  logLine(line);
};
net
  .createServer((s) => {
    s.setNoDelay(true);
    h.sockets.add(s);
    s.on('data', (d) => h.fromMaster(d));
    s.on('close', () => h.sockets.delete(s));
    s.on('error', () => h.sockets.delete(s));
  })
  .listen(Number(a.port), '127.0.0.1', () => say(`UART0 on 127.0.0.1:${a.port}`));
if (a.control) {
  net
    .createServer((s) => {
      let rest = '';
      s.on('data', (d) => {
        rest += d.toString();
        const lines = rest.split('\n');
        rest = lines.pop();
        for (const l of lines) s.write(`${JSON.stringify(h.control(l))}\n`);
      });
      s.on('error', () => {});
    })
    .listen(Number(a.control), '127.0.0.1', () => say(`control on 127.0.0.1:${a.control}`));
}
// Ends with the process that started it (`--parent PID`: xtask, whatever way it ends).
if (a.parent) {
  setInterval(() => {
    try {
      process.kill(Number(a.parent), 0);
    } catch {
      process.exit(0);
    }
  }, 500).unref();
}
h.loop();
