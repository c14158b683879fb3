//! Generates the TypeScript declaration of the pipeline options for the JS
//! package from the `Params` struct in `src/params.rs`: one optional
//! camelCase key per field, typed from the Rust type, documented with the
//! field's doc comment (which gives unit and default). `src/wasm/mod.rs`
//! includes it in the `.d.ts`, so the typings follow the parameters without a
//! second copy to keep in sync.
//!
//! The other interfaces of the `.d.ts` (the results, the options of single
//! calls) are generated from their Rust structs by `build/ts_interfaces.rs`,
//! into `interfaces.d.ts`.

use std::fs;
use std::path::Path;

#[path = "build/ts_interfaces.rs"]
mod ts_interfaces;

fn main() {
    println!("cargo:rerun-if-changed=src/params.rs");
    println!("cargo:rerun-if-changed=build.rs");
    let src = fs::read_to_string("src/params.rs").unwrap_or_default();
    let out = std::env::var("OUT_DIR").unwrap_or_else(|_| ".".into());
    // A failure to write is a build error worth seeing.
    if let Err(e) = fs::write(
        Path::new(&out).join("pipeline_options.d.ts"),
        pipeline_options_ts(&src),
    ) {
        panic!("cannot write the generated TypeScript: {e}");
    }
    ts_interfaces::write(Path::new(&out));
}

/// `snake_case` to `camelCase`.
fn camel(name: &str) -> String {
    let mut out = String::new();
    let mut upper = false;
    for c in name.chars() {
        if c == '_' {
            upper = true;
        } else if upper {
            out.extend(c.to_uppercase());
            upper = false;
        } else {
            out.push(c);
        }
    }
    out
}

/// The TypeScript type of a `Params` field's Rust type.
fn ts_type(rust: &str) -> &'static str {
    match rust {
        "f64" | "f32" | "usize" | "u64" | "u32" | "i64" | "i32" => "number",
        "bool" => "boolean",
        "HullKind" => "\"convex\" | \"concave\"",
        "SolidityKind" => "\"density\" | \"occupancy\"",
        "[f64; 3]" => "[number, number, number]",
        _ => "unknown",
    }
}

fn pipeline_options_ts(src: &str) -> String {
    let mut out = String::from(
        "/**\n * Options of the pipeline (detection and incremental scenario), generated\n \
         * from the Rust `Params`. Every key is optional: the preset's value is\n \
         * used for a missing key. An unknown key, a wrong type or an out-of-range\n \
         * value throws an Error naming the key. Distances in metres, areas in\n \
         * square metres, angles in degrees.\n */\nexport interface PipelineOptions {\n  \
         /** Starting values for every other key: \"gpp1\" (the paper's GPP 1, only\n   \
         * large polygons) or \"gpp2\" (GPP 2, small polygons too). Default \"gpp2\". */\n  \
         preset?: Preset;\n",
    );
    let body = src
        .split_once("pub struct Params {")
        .map(|(_, rest)| rest.split("\n}").next().unwrap_or(""))
        .unwrap_or("");
    let mut doc: Vec<String> = Vec::new();
    for line in body.lines().map(str::trim) {
        if let Some(d) = line.strip_prefix("///") {
            doc.push(d.trim().replace("*/", "* /"));
        } else if let Some(field) = line.strip_prefix("pub ") {
            if let Some((name, ty)) = field.split_once(':') {
                let ty = ty.trim().trim_end_matches(',').trim();
                out.push_str("  /**\n");
                for d in &doc {
                    out.push_str(&format!("   * {d}\n").replace("* \n", "*\n"));
                }
                out.push_str("   */\n");
                out.push_str(&format!("  {}?: {};\n", camel(name.trim()), ts_type(ty)));
            }
            doc.clear();
        } else if !line.starts_with("#[") {
            doc.clear();
        }
    }
    out.push_str("}\n");
    out
}
