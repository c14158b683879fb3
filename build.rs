//! Generates the TypeScript declaration of the pipeline options for the JS
//! package from the options table `src/params/table.rs` (which the crate
//! includes too): one optional camelCase key per option, typed from the Rust
//! type, documented with the option's doc comment (unit and default) and its
//! range. `src/wasm/mod.rs` includes it in the `.d.ts`, so the typings follow the
//! parameters without a second copy to keep in sync.
//!
//! The other interfaces of the `.d.ts` (the results, the options of single
//! calls) are generated from their Rust structs by `build/ts_interfaces.rs`,
//! into `interfaces.d.ts`.

use std::fs;
use std::path::Path;

#[path = "src/params/shared.rs"]
mod shared;
#[path = "build/ts_interfaces.rs"]
mod ts_interfaces;

use shared::{camel, Check};

fn main() {
    println!("cargo:rerun-if-changed=src/params/table.rs");
    println!("cargo:rerun-if-changed=build.rs");
    let out = std::env::var("OUT_DIR").unwrap_or_else(|_| ".".into());
    // A failure to write is a build error worth seeing.
    if let Err(e) = fs::write(
        Path::new(&out).join("pipeline_options.d.ts"),
        pipeline_options_ts(),
    ) {
        panic!("cannot write the generated TypeScript: {e}");
    }
    ts_interfaces::write(Path::new(&out));
}

/// The TypeScript type of a `Params` field's Rust type.
fn ts_type(rust: &str) -> String {
    match rust {
        "f64" | "f32" | "usize" | "u64" | "u32" | "i64" | "i32" => "number".into(),
        "bool" => "boolean".into(),
        // The outline methods and solidity tests, from their enums.
        "HullKind" => ts_interfaces::string_enum("src/outline/mod.rs", "HullKind"),
        "SolidityKind" => ts_interfaces::string_enum("src/params/mod.rs", "SolidityKind"),
        "[f64; 3]" => "[number, number, number]".into(),
        "Option<[f64; 3]>" => "[number, number, number] | null".into(),
        other => panic!("build.rs: no TypeScript type for the option type {other}"),
    }
}

/// One row of the options table.
struct Row {
    key: &'static str,
    ty: &'static str,
    docs: &'static [&'static str],
    unit: &'static str,
    check: Check,
}

macro_rules! options {
    ($( $(#[doc = $doc:literal])* $key:ident : $ty:ty = $($path:ident).+ , $unit:literal , $check:expr ; )*) => {
        fn option_rows() -> Vec<Row> {
            vec![$( Row {
                key: stringify!($key),
                ty: stringify!($ty),
                docs: &[$($doc),*],
                unit: $unit,
                check: $check,
            }, )*]
        }
    };
}

include!("src/params/table.rs");

fn pipeline_options_ts() -> String {
    let mut out = String::from(
        "/**\n * Options of the pipeline (detection and incremental scenario), generated\n \
         * from the options table of the Rust `Params`. Every key is optional: the\n \
         * preset's value is used for a missing key. An unknown key, a wrong type\n \
         * or an out-of-range value throws an Error naming the key. Distances in\n \
         * metres, areas in square metres, angles in degrees.\n */\nexport interface PipelineOptions {\n  \
         /** Starting values for every other key: \"gpp1\" (the paper's GPP 1, only\n   \
         * large polygons) or \"gpp2\" (GPP 2, small polygons too). Default \"gpp2\". */\n  \
         preset?: Preset;\n",
    );
    for row in option_rows() {
        out.push_str("  /**\n");
        for d in row.docs {
            let d = d.trim().replace("*/", "* /");
            out.push_str(&format!("   * {d}\n").replace("* \n", "*\n"));
        }
        if !row.unit.is_empty() {
            out.push_str(&format!("   * Unit: {}.\n", row.unit));
        }
        if let Some(range) = row.check.describe() {
            out.push_str(&format!("   * Range: {range}.\n"));
        }
        out.push_str("   */\n");
        out.push_str(&format!("  {}?: {};\n", camel(row.key), ts_type(row.ty)));
    }
    out.push_str("}\n");
    out
}
