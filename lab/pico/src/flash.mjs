// The Pico's 2 MiB QSPI flash as a file the harness owns: it survives a reset of the
// node and a restart of the harness. Erase and program behave as NOR flash (an erase
// sets 0xFF a 4 KiB sector at a time, a program only clears bits) and take the time
// the W25Q16JV's data sheet gives as typical (45 ms a sector, 0.4 ms a 256-byte
// page), during which the core waits in the ROM with interrupts masked. A power cut
// can be armed at the Nth erase or program from now, after a given number of points
// of it (bytes programmed, 4-byte words erased): those before it are done, the rest
// not, and the node loses power there.
import fs from 'node:fs';

export const FLASH_SIZE = 2 * 1024 * 1024;
export const SECTOR = 4096;
const ERASE_NS = 45e6;
const PAGE_PROGRAM_NS = 0.4e6;

export class FlashImage {
  constructor(path) {
    this.path = path;
    this.bytes = new Uint8Array(FLASH_SIZE).fill(0xff);
    if (fs.existsSync(path)) {
      const old = fs.readFileSync(path);
      this.bytes.set(old.subarray(0, FLASH_SIZE));
    }
    this.fd = fs.openSync(path, fs.existsSync(path) ? 'r+' : 'w+');
    this.save(0, FLASH_SIZE);
    this.ops = 0; // erases and programs since the harness started
    this.cut = null; // {op: ops count at which to cut, points}
    this.onCut = null; // called when a cut happened (the node loses power)
    this.onBusy = null; // called with the ns an operation takes
  }

  save(from, len) {
    fs.writeSync(this.fd, this.bytes, from, len, from);
  }

  /** The node's image: its segments in the flash's address range. */
  load(segments) {
    for (const { paddr, data } of segments) {
      const at = paddr - 0x10000000;
      if (at >= 0 && at + data.length <= FLASH_SIZE) {
        this.bytes.set(data, at);
        this.save(at, data.length);
      }
    }
  }

  /** Arms a power cut: the `nth` erase or program from now (1: the next), after `points`. */
  arm(nth, points) {
    this.cut = { op: this.ops + nth, points };
  }

  /** Whether this operation is cut, and after how many points. */
  cutPoints() {
    this.ops += 1;
    if (this.cut && this.cut.op === this.ops) {
      const { points } = this.cut;
      this.cut = null;
      return points;
    }
    return null;
  }

  erase(addr, count) {
    const from = addr & ~(SECTOR - 1);
    const to = Math.min(FLASH_SIZE, (addr + count + SECTOR - 1) & ~(SECTOR - 1));
    const cut = this.cutPoints();
    const end = cut === null ? to : Math.min(to, from + 4 * cut);
    this.bytes.fill(0xff, from, end);
    this.save(from, to - from);
    this.onBusy?.(ERASE_NS * ((to - from) / SECTOR));
    if (cut !== null) this.onCut?.();
  }

  program(addr, data) {
    const cut = this.cutPoints();
    const n = cut === null ? data.length : Math.min(data.length, cut);
    for (let i = 0; i < n && addr + i < FLASH_SIZE; i++) this.bytes[addr + i] &= data[i];
    this.save(addr, Math.min(data.length, FLASH_SIZE - addr));
    this.onBusy?.(PAGE_PROGRAM_NS * Math.ceil(data.length / 256));
    if (cut !== null) this.onCut?.();
  }
}
