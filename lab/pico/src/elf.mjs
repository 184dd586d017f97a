// The node's ELF: its loadable segments (to put into the flash image) and its symbols
// (the RTT control block, the stack's bounds). ELF32, little-endian, as rustc links
// for thumbv6m-none-eabi.

export function readElf(bytes) {
  const v = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (v.getUint32(0, false) !== 0x7f454c46 || bytes[4] !== 1 || bytes[5] !== 1) {
    throw new Error('not a 32-bit little-endian ELF');
  }
  const phoff = v.getUint32(28, true);
  const shoff = v.getUint32(32, true);
  const phentsize = v.getUint16(42, true);
  const phnum = v.getUint16(44, true);
  const shentsize = v.getUint16(46, true);
  const shnum = v.getUint16(48, true);
  const segments = [];
  for (let i = 0; i < phnum; i++) {
    const at = phoff + i * phentsize;
    const type = v.getUint32(at, true);
    const offset = v.getUint32(at + 4, true);
    const paddr = v.getUint32(at + 12, true);
    const filesz = v.getUint32(at + 16, true);
    if (type === 1 && filesz > 0) {
      segments.push({ paddr, data: bytes.subarray(offset, offset + filesz) });
    }
  }
  const sections = [];
  for (let i = 0; i < shnum; i++) {
    const at = shoff + i * shentsize;
    sections.push({
      type: v.getUint32(at + 4, true),
      addr: v.getUint32(at + 12, true),
      offset: v.getUint32(at + 16, true),
      size: v.getUint32(at + 20, true),
      link: v.getUint32(at + 24, true),
    });
  }
  const symbols = new Map();
  for (const s of sections.filter((s) => s.type === 2)) {
    const strtab = sections[s.link];
    for (let at = s.offset; at + 16 <= s.offset + s.size; at += 16) {
      const nameAt = strtab.offset + v.getUint32(at, true);
      let end = nameAt;
      while (bytes[end] !== 0) end++;
      const name = new TextDecoder().decode(bytes.subarray(nameAt, end));
      if (name) symbols.set(name, v.getUint32(at + 4, true));
    }
  }
  return { segments, symbols };
}
