#!/usr/bin/env node
// The table of JS options in docs/API.md, generated from the built package: the
// keys, types and doc comments of `PipelineOptions` in pkg/node's .d.ts
// (themselves generated from `Params` in src/params.rs by build.rs) and the
// presets' actual values from `defaultOptions()`.
//
//   node scripts/gen-js-docs.mjs          rewrite the table in docs/API.md
//   node scripts/gen-js-docs.mjs --check  exit 1 when docs/API.md is stale
//
// The Node tests import the helpers to check the docs against the values.
import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";
import { fileURLToPath } from "node:url";

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "..");
const START = "<!-- js-options:start -->";
const END = "<!-- js-options:end -->";

function pkg() {
  return createRequire(import.meta.url)(path.join(root, "pkg/node"));
}

/** key -> { doc, type } of `PipelineOptions` in the built .d.ts. */
export function optionDocs() {
  const dts = fs.readFileSync(path.join(root, "pkg/node/polyscene.d.ts"), "utf8");
  const start = dts.indexOf("export interface PipelineOptions");
  const block = dts.slice(start, dts.indexOf("\n}", start));
  const out = new Map();
  for (const m of block.matchAll(/\/\*\*((?:(?!\*\/)[\s\S])*)\*\/\s*(\w+)\?:\s*([^;]+);/g)) {
    const doc = m[1]
      .split("\n")
      .map((l) => l.replace(/^\s*\*\s?/, "").trim())
      .filter(Boolean)
      .join(" ");
    out.set(m[2], { doc, type: m[3].trim() });
  }
  return out;
}

/** The default a doc comment states ("Default 0.10", "gpp2 default 150", "Default `[0, 0, 0]`"). */
export function documentedDefault(doc) {
  const m =
    doc.match(/gpp2 default:?\s+([-+]?[\d.]+(?:e\d+)?)/i) ??
    doc.match(/Default:?\s+(`[^`]*`|"[^"]*"|\[[^\]]*\]|[-+]?[\d.]+(?:e\d+)?|true|false|[a-z]+)/);
  return m ? m[1].replace(/`/g, "").replace(/\.$/, "") : undefined;
}

/** Does a stated default (text) equal an actual value? */
export function sameValue(stated, value) {
  if (typeof value === "number") return Number(stated) === value;
  if (typeof value === "boolean") return stated === String(value);
  if (typeof value === "string") return stated.replace(/"/g, "") === value;
  try {
    return JSON.stringify(JSON.parse(stated)) === JSON.stringify(value);
  } catch {
    return false;
  }
}

/** The unit the options table declares (the generated "Unit: m." line). */
function unitOf(doc) {
  const m = doc.match(/Unit: (\S+)\./);
  return m ? m[1] : "";
}

function show(v) {
  if (v === undefined) return "";
  if (Array.isArray(v)) return `\`[${v.join(", ")}]\``;
  if (typeof v === "string") return `\`"${v}"\``;
  if (typeof v === "number" && v >= 1e6) return `\`${v.toExponential().replace("e+", "e")}\``;
  return `\`${v}\``;
}

/** The first sentence of a doc comment, without its unit and default (the
 * table has columns for them; the .d.ts keeps the whole text). */
function summary(doc) {
  const text = doc.replace(/\s*Unit: \S+\./, "").replace(/\s*Range: .*\.$/, "");
  const first = text.match(/^(.*?[.:])(\s|$)/);
  return (first ? first[1] : text).replace(/\s*\((m|m\^2|deg|0\.\.1)\)/, "").replace(/[.:]$/, "");
}

/** The markdown table of every option. */
export function optionsTable() {
  const { defaultOptions } = pkg();
  const gpp2 = defaultOptions("gpp2");
  const gpp1 = defaultOptions("gpp1");
  const esc = (s) => s.replace(/\|/g, "\\|");
  const rows = [
    "| Key | Type | Unit | Range | Default (gpp2) | gpp1 | Meaning |",
    "| --- | --- | --- | --- | --- | --- | --- |",
  ];
  for (const [key, { doc, type }] of optionDocs()) {
    const d = key === "preset" ? "gpp2" : gpp2[key];
    const g = key === "preset" ? undefined : JSON.stringify(gpp1[key]) !== JSON.stringify(d) ? gpp1[key] : undefined;
    const t = key === "preset" ? '"gpp1" \\| "gpp2"' : esc(type);
    const range = (doc.match(/Range: (.*)\.$/) ?? [])[1] ?? "";
    rows.push(`| \`${key}\` | ${t} | ${unitOf(doc)} | ${esc(range)} | ${show(d)} | ${show(g)} | ${esc(summary(doc))} |`);
  }
  return rows.join("\n");
}

if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const file = path.join(root, "docs/API.md");
  const readme = fs.readFileSync(file, "utf8");
  const [a, b] = [readme.indexOf(START), readme.indexOf(END)];
  if (a < 0 || b < a) {
    console.error(`docs/API.md has no ${START} ... ${END} block`);
    process.exit(1);
  }
  const next = `${readme.slice(0, a + START.length)}\n${optionsTable()}\n${readme.slice(b)}`;
  if (process.argv.includes("--check")) {
    if (next !== readme) {
      console.error("docs/API.md's options table is stale: run node scripts/gen-js-docs.mjs");
      process.exit(1);
    }
  } else if (next !== readme) {
    fs.writeFileSync(file, next);
    console.log("docs/API.md: options table updated");
  }
}
