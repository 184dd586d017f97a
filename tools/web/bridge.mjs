#!/usr/bin/env node
// A WebSocket-to-TCP bridge for the web console's Node view: a page cannot open a TCP
// socket, so this forwards the bytes of each WebSocket connection (binary messages)
// to a TCP port and back, one TCP connection per WebSocket. In front of a Modbus
// gateway's RTU-over-TCP port, a serial server, or the node in QEMU
// (`cargo xtask modbus --serve 5020`):
//
//     node tools/web/bridge.mjs 127.0.0.1:8502 127.0.0.1:5020
//
// then connect the console to ws://127.0.0.1:8502. Node.js 18 or later, no packages
// (RFC 6455 framing by hand). It listens on the loopback unless given another address:
// it carries whatever a page sends, so keep it off networks you do not trust.
import http from 'node:http';
import net from 'node:net';
import crypto from 'node:crypto';

const [listen, target] = process.argv.slice(2);
const split = (a, what) => {
  const i = a?.lastIndexOf(':') ?? -1;
  const port = Number(a?.slice(i + 1));
  if (i < 1 || !Number.isInteger(port) || port < 1 || port > 65535) {
    console.error(`bridge: ${what} ${a ?? '(missing)'}: HOST:PORT\nusage: node bridge.mjs LISTEN_HOST:PORT TCP_HOST:PORT`);
    process.exit(2);
  }
  return [a.slice(0, i), port];
};
const [host, port] = split(listen, 'listen');
const [toHost, toPort] = split(target, 'target');

/** One WebSocket frame of `payload` (server frames are not masked). */
function frame(opcode, payload) {
  const n = payload.length;
  const head = n < 126 ? Buffer.from([0x80 | opcode, n]) : n < 65536
    ? Buffer.from([0x80 | opcode, 126, n >> 8, n & 0xff])
    : Buffer.concat([Buffer.from([0x80 | opcode, 127]), (() => { const b = Buffer.alloc(8); b.writeBigUInt64BE(BigInt(n)); return b; })()]);
  return Buffer.concat([head, payload]);
}

const server = http.createServer((req, res) => {
  res.writeHead(426, { 'content-type': 'text/plain' });
  res.end('a WebSocket bridge to a TCP port: connect with ws://\n');
});

server.on('upgrade', (req, socket) => {
  const key = req.headers['sec-websocket-key'];
  if (!key || req.headers.upgrade?.toLowerCase() !== 'websocket') {
    socket.end('HTTP/1.1 400 Bad Request\r\n\r\n');
    return;
  }
  const accept = crypto.createHash('sha1').update(`${key}258EAFA5-E914-47DA-95CA-C5AB0DC85B11`).digest('base64');
  const tcp = net.connect(toPort, toHost);
  tcp.setNoDelay(true);
  let pending = Buffer.alloc(0);
  let message = [];
  const close = () => { tcp.destroy(); socket.destroy(); };
  tcp.on('connect', () => {
    socket.write(`HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: ${accept}\r\n\r\n`);
    console.log(`bridge: ${req.socket.remoteAddress} -> ${toHost}:${toPort}`);
  });
  tcp.on('data', (d) => socket.write(frame(0x2, d)));
  tcp.on('error', (e) => {
    console.error(`bridge: ${toHost}:${toPort}: ${e.message}`);
    if (!socket.destroyed) socket.end('HTTP/1.1 502 Bad Gateway\r\n\r\n');
  });
  tcp.on('close', () => socket.destroy());
  socket.on('error', close);
  socket.on('close', close);
  socket.on('data', (chunk) => {
    pending = Buffer.concat([pending, chunk]);
    for (;;) {
      if (pending.length < 2) return;
      const fin = pending[0] & 0x80, opcode = pending[0] & 0x0f, masked = pending[1] & 0x80;
      let n = pending[1] & 0x7f, at = 2;
      if (n === 126) { if (pending.length < 4) return; n = pending.readUInt16BE(2); at = 4; }
      else if (n === 127) { if (pending.length < 10) return; n = Number(pending.readBigUInt64BE(2)); at = 10; }
      if (!masked) { close(); return; } // a client's frames are masked (RFC 6455 5.1)
      if (pending.length < at + 4 + n) return;
      const mask = pending.subarray(at, at + 4);
      const payload = Buffer.from(pending.subarray(at + 4, at + 4 + n));
      for (let i = 0; i < n; i++) payload[i] ^= mask[i & 3];
      pending = pending.subarray(at + 4 + n);
      if (opcode === 0x8) { socket.end(frame(0x8, Buffer.alloc(0))); tcp.end(); return; }
      if (opcode === 0x9) { socket.write(frame(0xa, payload)); continue; }
      if (opcode === 0xa) continue;
      message.push(payload);
      if (fin) { tcp.write(Buffer.concat(message)); message = []; }
    }
  });
});

server.listen(port, host, () => console.log(`bridging ws://${host}:${port} to ${toHost}:${toPort}`));
