// UART0 as the PL011 behaves, in place of rp2040js's model (which lacks UARTIFLS and
// UARTDMACR, raises the TX interrupt on every status read, sends a byte the moment it
// is written and never reads BUSY): 32-byte FIFOs; bytes on the line take their
// character time (start, data, parity, stop bits at the programmed baud rate) in
// emulated time, both ways; BUSY while the transmitter holds a byte; the RX interrupt
// at the UARTIFLS level, the RX timeout 32 bit times after the last byte, the TX
// interrupt when the TX FIFO drains through its UARTIFLS level; an overrun when the RX
// FIFO is full. `sched` is the harness's scheduler (emulated ns).

const DR = 0x0, RSR = 0x4, FR = 0x18, IBRD = 0x24, FBRD = 0x28, LCR_H = 0x2c, CR = 0x30;
const IFLS = 0x34, IMSC = 0x38, RIS = 0x3c, MIS = 0x40, ICR = 0x44, DMACR = 0x48;
const RXI = 1 << 4, TXI = 1 << 5, RTI = 1 << 6, OEI = 1 << 10;
const DEPTH = 32;
const LEVELS = [4, 8, 16, 24, 28];
const IDS = { 0xfe0: 0x11, 0xfe4: 0x10, 0xfe8: 0x34, 0xfec: 0x00, 0xff0: 0x0d, 0xff4: 0xf0, 0xff8: 0x05, 0xffc: 0xb1 };

export class Uart {
  /**
   * `send(byte)`: a byte has left the transmitter (its stop bit sent); `sending(on)`:
   * the transmitter starts or ends a byte (the DE check).
   */
  constructor(mcu, peripheral, sched, send, sending) {
    this.mcu = mcu;
    this.p = peripheral;
    this.sched = sched;
    this.send = send;
    this.sending = sending;
    this.rx = [];
    this.tx = [];
    this.shifting = false;
    this.lineFreeAt = 0; // when the RX line is free for the next byte (ns)
    this.ris = 0;
    this.imsc = 0;
    this.ifls = 0x12;
    this.dmacr = 0;
    this.lcr = 0;
    this.cr = 0x300;
    this.ibrd = 0;
    this.fbrd = 0;
    this.rxTimeout = null;
    this.overruns = 0;
    this.received = 0; // bytes the node read
    this.sent = 0;
    peripheral.readUint32 = (offset) => this.read(offset);
    peripheral.writeUint32 = (offset, value) => this.write(offset, value);
  }

  /** The line's character time (ns). */
  charNs() {
    const div = this.ibrd + this.fbrd / 64;
    const baud = div ? this.mcu.clkPeri / (16 * div) : 115200;
    const bits = 1 + 5 + ((this.lcr >> 5) & 3) + (this.lcr & 2 ? 1 : 0) + (this.lcr & 8 ? 2 : 1);
    return (bits * 1e9) / baud;
  }

  fifos() {
    return !!(this.lcr & 0x10);
  }

  depth() {
    return this.fifos() ? DEPTH : 1;
  }

  update() {
    this.mcu.setInterrupt(this.p.irq, !!(this.ris & this.imsc));
  }

  rxLevel() {
    return this.fifos() ? LEVELS[Math.min(4, (this.ifls >> 3) & 7)] : 1;
  }

  txLevel() {
    return this.fifos() ? LEVELS[Math.min(4, this.ifls & 7)] : 0;
  }

  /** A byte from the master: on the line for a character time after the line is free. */
  receive(byte) {
    const now = this.sched.now();
    const at = Math.max(now, this.lineFreeAt) + this.charNs();
    this.lineFreeAt = at;
    this.sched.at(at, () => this.arrived(byte));
  }

  arrived(byte) {
    if (this.rx.length >= this.depth()) {
      this.overruns += 1;
      this.ris |= OEI;
    } else {
      this.rx.push(byte);
    }
    if (this.rx.length >= this.rxLevel()) this.ris |= RXI;
    this.sched.cancel(this.rxTimeout);
    this.rxTimeout = this.sched.at(this.sched.now() + (32 * this.charNs()) / 10, () => {
      this.rxTimeout = null;
      if (this.rx.length) {
        this.ris |= RTI;
        this.update();
      }
    });
    this.update();
  }

  startShift() {
    if (this.shifting || !this.tx.length) return;
    this.shifting = true;
    this.sending(true);
    this.sched.at(this.sched.now() + this.charNs(), () => {
      const before = this.tx.length;
      const byte = this.tx.shift();
      this.shifting = false;
      this.send(byte);
      if (before > this.txLevel() && this.tx.length <= this.txLevel()) this.ris |= TXI;
      this.update();
      if (this.tx.length) this.startShift();
      else this.sending(false);
    });
  }

  read(offset) {
    switch (offset) {
      case DR: {
        const byte = this.rx.length ? this.rx.shift() : 0;
        this.received += 1;
        if (this.rx.length < this.rxLevel()) this.ris &= ~RXI;
        if (!this.rx.length) this.ris &= ~RTI;
        this.update();
        return byte;
      }
      case RSR:
        return 0;
      case FR: {
        const busy = this.shifting || this.tx.length > 0;
        return (
          (this.tx.length === 0 ? 1 << 7 : 0) |
          (this.rx.length >= this.depth() ? 1 << 6 : 0) |
          (this.tx.length >= this.depth() ? 1 << 5 : 0) |
          (this.rx.length === 0 ? 1 << 4 : 0) |
          (busy ? 1 << 3 : 0)
        );
      }
      case IBRD:
        return this.ibrd;
      case FBRD:
        return this.fbrd;
      case LCR_H:
        return this.lcr;
      case CR:
        return this.cr;
      case IFLS:
        return this.ifls;
      case IMSC:
        return this.imsc;
      case RIS:
        return this.ris;
      case MIS:
        return this.ris & this.imsc;
      case DMACR:
        return this.dmacr;
    }
    return IDS[offset] ?? 0;
  }

  write(offset, value) {
    switch (offset) {
      case DR:
        if (this.tx.length < this.depth()) this.tx.push(value & 0xff);
        if (this.tx.length > this.txLevel()) this.ris &= ~TXI;
        this.update();
        this.startShift();
        return;
      case RSR:
        return;
      case IBRD:
        this.ibrd = value & 0xffff;
        return;
      case FBRD:
        this.fbrd = value & 0x3f;
        return;
      case LCR_H:
        this.lcr = value & 0xff;
        return;
      case CR:
        this.cr = value & 0xffff;
        return;
      case IFLS:
        this.ifls = value & 0x3f;
        return;
      case IMSC:
        this.imsc = value & 0x7ff;
        this.update();
        return;
      case ICR:
        this.ris &= ~this.p.rawWriteValue;
        this.update();
        return;
      case DMACR:
        this.dmacr = value & 7;
        return;
    }
  }
}
