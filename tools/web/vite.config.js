// The console's build: one static folder (relative paths, so that any static server
// serves it from any path, offline), the WebAssembly binding from `cargo xtask web`
// (MISALIGN_WEB_PKG, its wasm-bindgen output) and the register map from docs/.
import { defineConfig } from 'vite';
import { fileURLToPath } from 'node:url';
import path from 'node:path';

const here = path.dirname(fileURLToPath(import.meta.url));
const root = path.resolve(here, '../..');
const pkg = process.env.MISALIGN_WEB_PKG ?? path.join(root, 'target/web-console/pkg');

export default defineConfig({
  root: here,
  base: './',
  resolve: { alias: { '@pkg': pkg } },
  worker: { format: 'es' },
  build: {
    outDir: process.env.MISALIGN_WEB_OUT ?? path.join(root, 'target/web-console/dist'),
    emptyOutDir: true,
    target: 'es2022',
    assetsInlineLimit: 0,
    reportCompressedSize: false,
  },
  server: { fs: { allow: [root] } },
});
