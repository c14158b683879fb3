// proj4 as an ES module for the pages: its npm package ships a UMD build
// (dist/proj4-src.js), which, run as a module, sets globalThis.proj4. The
// pages' import map points the bare 'proj4' (imported by polyscene/geo) here.
import '../node_modules/proj4/dist/proj4-src.js';

export default globalThis.proj4;
