// A Modbus RTU master over any transport (transport.js): one request at a time, the
// answer found by its function's length and checked by its CRC, a node that does not
// answer reported as such.

const CRC_TABLE = (() => {
  const t = new Uint16Array(256);
  for (let i = 0; i < 256; i++) {
    let c = i;
    for (let k = 0; k < 8; k++) c = c & 1 ? (c >>> 1) ^ 0xa001 : c >>> 1;
    t[i] = c;
  }
  return t;
})();

/** CRC-16/MODBUS. */
export function crc16(bytes) {
  let crc = 0xffff;
  for (const b of bytes) crc = (crc >>> 8) ^ CRC_TABLE[(crc ^ b) & 0xff];
  return crc;
}

/** `bytes` end in their CRC-16/MODBUS, low byte first. */
export function crcOk(bytes) {
  const crc = crc16(bytes.slice(0, -2));
  return bytes.at(-2) === (crc & 0xff) && bytes.at(-1) === crc >> 8;
}

/** What each exception code means (the Modbus specification's names). */
const EXCEPTIONS = {
  1: 'illegal function',
  2: 'illegal data address',
  3: 'illegal data value',
  4: 'server device failure',
};

/** A request the node answered with an exception. */
export class Refused extends Error {
  constructor(what, code) {
    super(`${what}: refused with exception ${code} (${EXCEPTIONS[code] ?? 'unknown'})`);
    this.code = code;
  }
}

/** A node that did not answer in time. */
export class Silent extends Error {}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

export class Client {
  /** `unit`: the node's unit id (1 to 247); `timeoutMs` per answer. */
  constructor(transport, { unit = 1, timeoutMs = 1000 } = {}) {
    if (!(Number.isInteger(unit) && unit >= 1 && unit <= 247)) {
      throw new Error(`unit id ${unit}: 1 to 247`);
    }
    this.t = transport;
    this.unit = unit;
    this.timeoutMs = timeoutMs;
    this.queue = Promise.resolve();
    this.buffer = [];
    this.t.onbytes = (bytes) => {
      for (const b of bytes) this.buffer.push(b);
      this.wake?.();
    };
  }

  /** The answer's PDU to `pdu` (function code first), requests one after another. */
  request(pdu, what) {
    const run = this.queue.then(() => this.exchange(Uint8Array.from(pdu), what));
    this.queue = run.catch(() => {});
    return run;
  }

  async exchange(pdu, what) {
    const frame = new Uint8Array(pdu.length + 3);
    frame[0] = this.unit;
    frame.set(pdu, 1);
    const crc = crc16(frame.subarray(0, pdu.length + 1));
    frame[pdu.length + 1] = crc & 0xff;
    frame[pdu.length + 2] = crc >> 8;
    if (this.t.silenceMs) await sleep(this.t.silenceMs);
    this.buffer = [];
    await this.t.write(frame);
    const deadline = performance.now() + this.timeoutMs;
    for (;;) {
      const answer = this.complete(pdu[0]);
      if (answer) {
        if (answer[1] & 0x80) throw new Refused(what, answer[2]);
        return answer.slice(1, -2);
      }
      const left = deadline - performance.now();
      if (left <= 0) {
        throw new Silent(
          `${what}: the node did not answer within ${this.timeoutMs} ms (its unit id ${this.unit}, ` +
            `the line settings, the cable or the bridge?)`,
        );
      }
      await new Promise((resolve) => {
        const timer = setTimeout(resolve, left);
        this.wake = () => { clearTimeout(timer); resolve(); };
      });
      this.wake = null;
    }
  }

  /** A read of `n` holding registers from `address` sent to `unit` as bytes, and
   * every byte that comes back within `timeoutMs` (less once one whole valid answer
   * is in), so that garbled bytes (two nodes answering at once) are seen rather than
   * taken for silence. */
  probe(unit, address, n, timeoutMs) {
    const run = this.queue.then(async () => {
      const frame = [unit, 3, address >> 8, address & 0xff, n >> 8, n & 0xff];
      const crc = crc16(frame);
      frame.push(crc & 0xff, crc >> 8);
      if (this.t.silenceMs) await sleep(this.t.silenceMs);
      this.buffer = [];
      await this.t.write(Uint8Array.from(frame));
      const deadline = performance.now() + timeoutMs;
      const whole = () => {
        const b = this.buffer;
        return b.length === 5 + 2 * n && b[0] === unit && b[1] === 3 && b[2] === 2 * n && crcOk(b);
      };
      while (!whole()) {
        const left = deadline - performance.now();
        if (left <= 0) break;
        await new Promise((resolve) => {
          const timer = setTimeout(resolve, left);
          this.wake = () => { clearTimeout(timer); resolve(); };
        });
        this.wake = null;
      }
      const got = Uint8Array.from(this.buffer);
      this.buffer = [];
      return got;
    });
    this.queue = run.catch(() => {});
    return run;
  }

  /** The whole answer in the buffer, or null while bytes are missing. */
  complete(fn) {
    const b = this.buffer;
    // Bytes before the unit's answer (another unit, line noise) are dropped.
    while (b.length && b[0] !== this.unit) b.shift();
    if (b.length < 5) return null;
    let n;
    if (b[1] === (fn | 0x80)) n = 5;
    else if (b[1] !== fn) { b.shift(); return this.complete(fn); }
    else if (fn <= 4) n = 5 + b[2];
    else n = 8;
    if (b.length < n) return null;
    const answer = Uint8Array.from(b.slice(0, n));
    if (!crcOk(answer)) {
      throw new Error('a damaged answer (its CRC does not match): noise on the line, or another master');
    }
    return answer;
  }

  /** Registers `n` from `address` (function 3 holding, 4 input). */
  async readRegisters(fn, address, n, what) {
    const a = await this.request([fn, address >> 8, address & 0xff, n >> 8, n & 0xff], what);
    const words = [];
    for (let i = 0; i < n; i++) words.push((a[2 + 2 * i] << 8) | a[3 + 2 * i]);
    return words;
  }

  /** Bits `n` from `address` (function 1 coils, 2 discrete inputs). */
  async readBits(fn, address, n, what) {
    const a = await this.request([fn, address >> 8, address & 0xff, n >> 8, n & 0xff], what);
    return Array.from({ length: n }, (_, i) => (a[2 + (i >> 3)] >> (i & 7)) & 1);
  }

  /** Function 16: `words` from `address`. */
  async writeRegisters(address, words, what) {
    const n = words.length;
    const pdu = [16, address >> 8, address & 0xff, n >> 8, n & 0xff, 2 * n];
    for (const w of words) pdu.push(w >> 8, w & 0xff);
    await this.request(pdu, what);
  }

  /** Function 5: one coil on or off. */
  async writeCoil(address, on, what) {
    await this.request([5, address >> 8, address & 0xff, on ? 0xff : 0, 0], what);
  }
}
