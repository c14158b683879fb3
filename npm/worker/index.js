// polyscene/worker: polyscene in a module Web Worker. PolysceneClient (this
// thread) starts ./worker.js, which loads the wasm and runs scans and
// detections off the main thread; see client.js and the PROTOCOL in
// worker.js.
export { PolysceneClient } from './client.js';
