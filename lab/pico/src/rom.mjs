// The boot ROM the node calls, written here (no ROM binary): rp2040js starts the node
// at its vector table, so nothing of the real ROM runs, but embassy-rp's flash driver
// looks up and calls the ROM's public functions. The ROM area holds the lookup
// table's pointers (datasheet 2.8.2: magic 'Mu' 1 at 0x10, the function table's
// pointer at 0x14, the data table's at 0x16, rom_table_lookup's at 0x18) and, for
// each function, a two-instruction stub: BKPT #n, BX LR. rp2040js hands the BKPT to
// the harness, which does the function's work (on the flash image it owns, on memory)
// and returns through the BX LR.

const FUNC_TABLE = 0x100;
const DATA_TABLE = 0x1c0;
const STUBS = 0x200;

// The functions: their two-letter codes, in stub order (stub 0 is rom_table_lookup).
const FUNCTIONS = [
  'IF', // connect_internal_flash
  'EX', // flash_exit_xip
  'RE', // flash_range_erase(addr, count, block_size, block_cmd)
  'RP', // flash_range_program(addr, data, count)
  'FC', // flash_flush_cache
  'CX', // flash_enter_cmd_xip
  'C4', // memcpy44(dest, src, n)
  'MC', // memcpy(dest, src, n)
  'MS', // memset(ptr, c, n)
  'M4', // memset4(ptr, c, n)
  'P3', // popcount32
  'R3', // reverse32
  'L3', // clz32
  'T3', // ctz32
  'UB', // reset_to_usb_boot
];

const code = (s) => s.charCodeAt(0) | (s.charCodeAt(1) << 8);

/** Writes the ROM's tables and stubs into `mcu.bootrom`. */
export function installRom(mcu) {
  const rom = new Uint8Array(mcu.bootrom.buffer);
  const view = new DataView(mcu.bootrom.buffer);
  rom.fill(0);
  rom.set([0x4d, 0x75, 0x01, 0x03], 0x10); // 'M' 'u' 1, version 3 (RP2040 B2)
  view.setUint16(0x14, FUNC_TABLE, true);
  view.setUint16(0x16, DATA_TABLE, true);
  view.setUint16(0x18, STUBS | 1, true);
  const stub = (n) => {
    view.setUint16(STUBS + 4 * n, 0xbe00 | n, true); // BKPT #n
    view.setUint16(STUBS + 4 * n + 2, 0x4770, true); // BX LR
    return STUBS + 4 * n;
  };
  stub(0);
  FUNCTIONS.forEach((name, i) => {
    view.setUint16(FUNC_TABLE + 4 * i, code(name), true);
    view.setUint16(FUNC_TABLE + 4 * i + 2, stub(i + 1) | 1, true);
  });
  view.setUint16(FUNC_TABLE + 4 * FUNCTIONS.length, 0, true);
  view.setUint16(DATA_TABLE, 0, true);
}

/**
 * The harness's side of the ROM: `onBreak(n)` for the stubs. `flash` is the
 * FlashImage; `log` names what it was asked that it does not provide.
 */
export function romHandler(mcu, flash, log) {
  const core = mcu.core;
  const r = core.registers;
  const read8 = (a) => mcu.readUint8(a >>> 0);
  const write8 = (a, v) => mcu.writeUint8(a >>> 0, v & 0xff);
  return (n) => {
    if (n === 0) {
      // rom_table_lookup(table, code): the table's entries are (code, address) pairs.
      const table = r[0];
      const wanted = r[1] & 0xffff;
      for (let at = table; ; at += 4) {
        const c = mcu.readUint16(at);
        if (c === 0) {
          log(`rom: no function ${String.fromCharCode(wanted & 0xff, wanted >> 8)}`);
          r[0] = 0;
          return;
        }
        if (c === wanted) {
          r[0] = mcu.readUint16(at + 2);
          return;
        }
      }
    }
    const name = FUNCTIONS[n - 1];
    switch (name) {
      case 'IF':
      case 'EX':
      case 'FC':
      case 'CX':
        return;
      case 'RE':
        flash.erase(r[0], r[1]);
        return;
      case 'RP': {
        const bytes = new Uint8Array(r[2]);
        for (let i = 0; i < bytes.length; i++) bytes[i] = read8(r[1] + i);
        flash.program(r[0], bytes);
        return;
      }
      case 'C4':
      case 'MC': {
        const [dest, src, len] = [r[0], r[1], r[2]];
        const tmp = new Uint8Array(len);
        for (let i = 0; i < len; i++) tmp[i] = read8(src + i);
        for (let i = 0; i < len; i++) write8(dest + i, tmp[i]);
        r[0] = dest;
        return;
      }
      case 'MS':
      case 'M4': {
        for (let i = 0; i < r[2]; i++) write8(r[0] + i, r[1]);
        return;
      }
      case 'P3': {
        let x = r[0] >>> 0;
        let c = 0;
        while (x) {
          c += x & 1;
          x >>>= 1;
        }
        r[0] = c;
        return;
      }
      case 'R3': {
        let x = r[0] >>> 0;
        let y = 0;
        for (let i = 0; i < 32; i++) {
          y = (y << 1) | (x & 1);
          x >>>= 1;
        }
        r[0] = y >>> 0;
        return;
      }
      case 'L3':
        r[0] = Math.clz32(r[0]);
        return;
      case 'T3': {
        const x = r[0] >>> 0;
        r[0] = x === 0 ? 32 : 31 - Math.clz32(x & -x);
        return;
      }
      default:
        log(`rom: ${name ?? `stub ${n}`} called, not provided`);
    }
  };
}
