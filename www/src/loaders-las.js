// @loaders.gl/las as an ES module for the pages (polyscene/io imports it on
// the first LAS/LAZ file): its npm package ships a self-contained UMD build
// (dist/dist.min.js, its dependencies inside), which, run as a module, sets
// globalThis.loaders. The map page's import map points '@loaders.gl/las' here.
import '../node_modules/@loaders.gl/las/dist/dist.min.js';

export const { LASLoader } = globalThis.loaders;
