// The byte link to a node, one small interface for every way of reaching it:
//
//   await t.open();   t.write(bytes);   t.onbytes = (bytes) => ...;   await t.close();
//   t.name            (what the page shows)
//   t.silenceMs       (the line's silence the master keeps between frames)
//   t.line(), await t.reconfigure(baud, parity)   (a serial port only: its settings)
//
// Web Serial (Chrome, Edge: a USB RS-485 adapter at the node's line settings), a
// WebSocket to a TCP port (a gateway or the repository's bridge, tools/web/bridge.mjs,
// in front of a node that carries RTU frames over TCP), or the node in the page.

/** The line settings a node's UART uses: 8 data bits, even parity, 1 stop bit by
 * default (Modbus RTU's); no parity takes 2 stop bits, as Modbus asks. */
export function lineSettings(baud, parity) {
  const names = { E: 'even', O: 'odd', N: 'none' };
  if (!names[parity]) throw new Error(`parity ${parity}: E, O or N`);
  if (!(Number.isInteger(baud) && baud >= 1200 && baud <= 1000000)) {
    throw new Error(`baud rate ${baud}: a whole number from 1200 to 1000000`);
  }
  return { baudRate: baud, dataBits: 8, parity: names[parity], stopBits: parity === 'N' ? 2 : 1 };
}

/** Web Serial: a port the person picks, opened at the node's line settings. */
export class SerialTransport {
  constructor(baud = 19200, parity = 'E') {
    this.set(baud, parity);
    this.onbytes = () => {};
  }

  set(baud, parity) {
    this.settings = lineSettings(baud, parity);
    this.baud = baud;
    this.parity = parity;
    this.name = `serial ${baud} baud, 8${parity}${this.settings.stopBits}`;
    // 3.5 characters of 11 bits, at least 1.75 ms (the RTU rule above 19200 baud).
    this.silenceMs = Math.max(1.75, (3.5 * 11 * 1000) / baud);
  }

  /** The line settings the port runs: {baud, parity}. */
  line() {
    return { baud: this.baud, parity: this.parity };
  }

  async open() {
    if (!('serial' in navigator)) {
      throw new Error('this browser has no Web Serial: use Chrome or Edge, or a WebSocket to a gateway');
    }
    this.port = await navigator.serial.requestPort();
    await this.start();
  }

  async start() {
    this.closing = false;
    await this.port.open(this.settings);
    this.writer = this.port.writable.getWriter();
    this.reading = this.readLoop();
  }

  /** The same port at other line settings (the node moved to them): closed and
   * opened again, without asking the person for the port. */
  async reconfigure(baud, parity) {
    if (baud === this.baud && parity === this.parity) return;
    await this.close();
    this.set(baud, parity);
    await this.start();
  }

  async readLoop() {
    while (this.port?.readable) {
      this.reader = this.port.readable.getReader();
      try {
        for (;;) {
          const { value, done } = await this.reader.read();
          if (done) return;
          if (value) this.onbytes(value);
        }
      } catch {
        // A framing or parity error ends this reader; the next one goes on.
      } finally {
        this.reader.releaseLock();
      }
      if (this.closing) return;
    }
  }

  async write(bytes) {
    await this.writer.write(bytes);
  }

  async close() {
    this.closing = true;
    await this.reader?.cancel().catch(() => {});
    await this.reading?.catch(() => {});
    this.writer?.releaseLock();
    await this.port?.close().catch(() => {});
    this.reader = null;
    this.writer = null;
  }
}

/** A WebSocket whose binary messages are the bytes of a TCP stream carrying RTU
 * frames (a Modbus gateway's RTU-over-TCP port through tools/web/bridge.mjs). */
export class WebSocketTransport {
  constructor(url) {
    if (!/^wss?:\/\//.test(url)) throw new Error(`${url}: a ws:// or wss:// address`);
    this.url = url;
    this.name = `WebSocket ${url}`;
    this.silenceMs = 0;
    this.onbytes = () => {};
  }

  open() {
    return new Promise((resolve, reject) => {
      const ws = new WebSocket(this.url);
      ws.binaryType = 'arraybuffer';
      ws.onopen = () => { this.ws = ws; resolve(); };
      ws.onerror = () => reject(new Error(`cannot connect to ${this.url}: is the bridge running?`));
      ws.onmessage = (m) => this.onbytes(new Uint8Array(m.data));
      ws.onclose = () => { this.ws = null; };
    });
  }

  async write(bytes) {
    if (!this.ws) throw new Error(`${this.url}: the connection closed`);
    this.ws.send(bytes);
  }

  async close() {
    this.ws?.close();
    this.ws = null;
  }
}

/** The node in the page (`PageNode` of the WebAssembly): the library's own server
 * over the built-in scenario, to try the console on, or to check a configuration. */
export class PageTransport {
  constructor(node) {
    this.node = node;
    this.name = 'the node in this page';
    this.silenceMs = 0;
    this.onbytes = () => {};
    this.start = performance.now();
  }

  async open() {}

  async write(bytes) {
    this.node.tick(Math.floor(performance.now() - this.start) >>> 0);
    const answer = this.node.request(bytes);
    if (answer.length) setTimeout(() => this.onbytes(answer), 0);
  }

  async close() {}
}
