// A module resolution hook for the tests of the repo's own JS modules (js/):
// a bare import (proj4) that nothing nearer provides resolves from
// www/node_modules, where scripts/setup.sh installs the page's packages.
// Installed as a package, the same import resolves from its dependencies.
import { createRequire } from "node:module";
import { pathToFileURL } from "node:url";

const wwwRequire = createRequire(new URL("../../www/package.json", import.meta.url));

export async function resolve(specifier, context, next) {
  try {
    return await next(specifier, context);
  } catch (e) {
    if (e?.code !== "ERR_MODULE_NOT_FOUND" || /^(\.|\/|[a-z]+:)/.test(specifier)) throw e;
    return { url: pathToFileURL(wwwRequire.resolve(specifier)).href, shortCircuit: true };
  }
}
