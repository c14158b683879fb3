// A module resolution hook for the tests of the repo's own JS modules (js/):
// a bare import (proj4) that nothing nearer provides resolves from
// www/node_modules, where scripts/setup.sh installs the page's packages.
// Installed as a package, the same import resolves from its dependencies.
const www = new URL("../../www/package.json", import.meta.url).href;

export async function resolve(specifier, context, next) {
  try {
    return await next(specifier, context);
  } catch (e) {
    if (e?.code !== "ERR_MODULE_NOT_FOUND" || /^(\.|\/|[a-z]+:)/.test(specifier)) throw e;
    // Resolved as an import from www/ (the ES module entry, as a bundler or
    // an installed package gets), not through require (CommonJS entry).
    return next(specifier, { ...context, parentURL: www });
  }
}
