//! Rust struct -> TypeScript interface, for the JS package's `.d.ts`.
//!
//! Every interface of the package that mirrors a Rust struct is generated
//! here from that struct's source: the struct's doc comment, then one key per
//! `pub` field, camelCase, typed from the Rust type (see [`ts_type`]) and
//! documented with the field's doc comment. `src/wasm/mod.rs` includes the
//! output (`interfaces.d.ts`) in the main module's `.d.ts` and
//! `src/wasm/sim.rs` includes `sim_interfaces.d.ts` in the simulator's, so
//! the typings cannot drift from the values the binding builds (the views in
//! `src/wasm/convert.rs` and `src/wasm/sim.rs` set their keys by hand: `tests/js/api.test.mjs` compares every object's
//! keys with its interface).
//!
//! A deliberately small parser: a struct is `pub struct Name {` up to the
//! first line that is `}`, one field per line, `///` doc comments and
//! `#[...]` attributes before it. Anything it cannot type fails the build.

use std::collections::HashMap;
use std::fs;
use std::path::Path;

/// Every interface of the main module's `.d.ts` (`polyscene`) that mirrors a
/// Rust struct, in the order of the `.d.ts`.
const INTERFACES: &[Interface] = &[
    Interface {
        ts: "ScenarioOptions",
        file: "src/wasm/convert.rs",
        rust: "ScenarioOptions",
        optional: true,
        flatten: &["params"],
    },
    Interface {
        ts: "DetectOptions",
        file: "src/wasm/convert.rs",
        rust: "DetectOptions",
        optional: true,
        flatten: &["params"],
    },
    Interface {
        ts: "ScanOptions",
        file: "src/wasm/convert.rs",
        rust: "ScanOptions",
        optional: true,
        flatten: &[],
    },
    Interface {
        ts: "Polygon",
        file: "src/wasm/convert.rs",
        rust: "PolygonView",
        optional: false,
        flatten: &[],
    },
    Interface {
        ts: "MergeEvent",
        file: "src/merge/mod.rs",
        rust: "MergeEvent",
        optional: false,
        flatten: &[],
    },
    Interface {
        ts: "StageTimes",
        file: "src/scenario/mod.rs",
        rust: "StageTimes",
        optional: false,
        flatten: &[],
    },
    Interface {
        ts: "Alignment",
        file: "src/scenario/mod.rs",
        rust: "Alignment",
        optional: false,
        flatten: &[],
    },
    Interface {
        ts: "ScanReport",
        file: "src/scenario/mod.rs",
        rust: "ScanReport",
        optional: false,
        flatten: &[],
    },
    Interface {
        ts: "Mesh",
        file: "src/wasm/convert.rs",
        rust: "MeshView",
        optional: false,
        flatten: &[],
    },
    Interface {
        ts: "FlatPolygons",
        file: "src/wasm/flat.rs",
        rust: "FlatPolygonsView",
        optional: false,
        flatten: &[],
    },
];

/// The same for the simulator's module (`polyscene/sim`, the `wasm-sim`
/// feature): `src/wasm/sim.rs` includes them from `sim_interfaces.d.ts`.
const SIM_INTERFACES: &[Interface] = &[
    Interface {
        ts: "SimulateOptions",
        file: "src/wasm/sim.rs",
        rust: "SimulateOptions",
        optional: true,
        flatten: &[],
    },
    Interface {
        ts: "SimulatedScan",
        file: "src/wasm/sim.rs",
        rust: "ScanView",
        optional: false,
        flatten: &[],
    },
    Interface {
        ts: "GroundTruthPolygon",
        file: "src/wasm/sim.rs",
        rust: "GroundTruthView",
        optional: false,
        flatten: &[],
    },
];

/// Rust enums that are strings in JS (their serde names): inlined as unions.
const STRING_ENUMS: &[StringEnum] = &[
    StringEnum {
        file: "src/sim/truth.rs",
        rust: "Layout",
    },
    StringEnum {
        file: "src/sim/truth.rs",
        rust: "SurfaceKind",
    },
];

/// Writes `interfaces.d.ts` (the interfaces of [`INTERFACES`]) and
/// `sim_interfaces.d.ts` (those of [`SIM_INTERFACES`]) into `out`.
pub fn write(out: &Path) {
    println!("cargo:rerun-if-changed=build/ts_interfaces.rs");
    for (file, interfaces) in [
        ("interfaces.d.ts", INTERFACES),
        ("sim_interfaces.d.ts", SIM_INTERFACES),
    ] {
        let ts = interfaces_ts(interfaces, STRING_ENUMS, read_source);
        if let Err(e) = fs::write(out.join(file), ts) {
            panic!("cannot write the generated TypeScript: {e}");
        }
    }
}

/// One generated interface.
struct Interface {
    /// Name in TypeScript.
    ts: &'static str,
    /// File of the Rust struct (relative to the crate root).
    file: &'static str,
    /// The Rust struct's name.
    rust: &'static str,
    /// Every key optional (`key?: T`): option objects.
    optional: bool,
    /// Fields whose keys are flattened into the object (the interface
    /// `extends` their type's interface instead of holding them).
    flatten: &'static [&'static str],
}

/// A Rust enum serialised as its variant names: a TS union of strings.
struct StringEnum {
    /// File of the Rust enum.
    file: &'static str,
    /// The Rust enum's name.
    rust: &'static str,
}

/// A `///` doc comment and a `pub` item of a struct or enum body.
struct Item {
    doc: Vec<String>,
    attrs: Vec<String>,
    line: String,
}

/// The doc comment and attributes of item `keyword name` in `src`, and the
/// items of its body.
fn parse(
    src: &str,
    keyword: &str,
    name: &str,
    file: &str,
) -> (Vec<String>, Vec<String>, Vec<Item>) {
    let head = format!("pub {keyword} {name} {{");
    let Some(at) = src.find(&head) else {
        panic!("build.rs: `{head}` not found in {file}");
    };
    // Doc comment and attributes: the lines just above, up to a blank line
    // or anything else.
    let mut doc = Vec::new();
    let mut attrs = Vec::new();
    for line in src[..at].lines().rev().map(str::trim) {
        if let Some(d) = line.strip_prefix("///") {
            doc.push(clean(d));
        } else if line.starts_with("#[") {
            attrs.push(line.to_string());
        } else {
            break;
        }
    }
    doc.reverse();
    let body = src[at + head.len()..].split("\n}").next().unwrap_or("");
    let mut items = Vec::new();
    let mut item = Item {
        doc: Vec::new(),
        attrs: Vec::new(),
        line: String::new(),
    };
    for line in body.lines().map(str::trim) {
        if let Some(d) = line.strip_prefix("///") {
            item.doc.push(clean(d));
        } else if line.starts_with("#[") {
            item.attrs.push(line.to_string());
        } else if line.is_empty() || line.starts_with("//") {
            continue;
        } else {
            item.line = line.trim_end_matches(',').to_string();
            items.push(std::mem::replace(
                &mut item,
                Item {
                    doc: Vec::new(),
                    attrs: Vec::new(),
                    line: String::new(),
                },
            ));
        }
    }
    (doc, attrs, items)
}

/// A doc comment line as JSDoc text: no `*/`, Rust intra-doc links as plain
/// code (`` [`A`](path) `` and `` [`A`] `` become `` `A` ``).
fn clean(line: &str) -> String {
    let mut s = line.strip_prefix(' ').unwrap_or(line).replace("*/", "* /");
    while let Some(start) = s.find("[`") {
        let Some(close) = s[start..].find("`]").map(|i| start + i) else {
            break;
        };
        let code = s[start + 1..close + 1].to_string();
        let mut end = close + 2;
        if s[end..].starts_with('(') {
            if let Some(p) = s[end..].find(')') {
                end += p + 1;
            }
        }
        s.replace_range(start..end, &code);
    }
    s
}

/// A variant name as serde writes it under `rename_all` (`None`: as is).
fn rename(name: &str, rule: Option<&str>) -> String {
    match rule {
        Some("lowercase") => name.to_lowercase(),
        Some("camelCase") => {
            let mut c = name.chars();
            c.next()
                .map(|f| f.to_lowercase().chain(c).collect())
                .unwrap_or_default()
        }
        Some("snake_case") => {
            let mut out = String::new();
            for (i, ch) in name.chars().enumerate() {
                if ch.is_uppercase() && i > 0 {
                    out.push('_');
                }
                out.extend(ch.to_lowercase());
            }
            out
        }
        _ => name.to_string(),
    }
}

/// The `rename_all` rule among serde attributes.
fn rename_all(attrs: &[String]) -> Option<&str> {
    attrs.iter().find_map(|a| {
        let rest = a.split_once("rename_all = \"")?.1;
        rest.split('"').next()
    })
}

/// Writes a JSDoc comment at `indent`: one line when the doc is one line.
fn jsdoc(out: &mut String, indent: &str, doc: &[String]) {
    match doc {
        [] => {}
        [one] => out.push_str(&format!("{indent}/** {one} */\n")),
        lines => {
            out.push_str(&format!("{indent}/**\n"));
            for l in lines {
                if l.is_empty() {
                    out.push_str(&format!("{indent} *\n"));
                } else {
                    out.push_str(&format!("{indent} * {l}\n"));
                }
            }
            out.push_str(&format!("{indent} */\n"));
        }
    }
}

/// Known names: Rust type -> TypeScript type (generated interfaces and
/// string enums; the fixed table is in [`ts_type`]).
struct Types(HashMap<String, String>);

/// The TypeScript type of a Rust type. Numbers, `bool`, strings, glam's
/// `DVec3` (a `[x, y, z]` array) and `DMat4` (a pose as the binding reads
/// it), JS typed arrays as themselves, `Exactly<N>` as the literal `N`,
/// `[T; N]` as a tuple, `Vec<T>` as `T[]`, `Option<T>` as `T` (the key
/// becomes optional), generated interfaces and string enums by `types`.
fn ts_type(rust: &str, types: &Types) -> String {
    let rust = rust.trim();
    if let Some(inner) = rust.strip_prefix("Vec<").and_then(|r| r.strip_suffix('>')) {
        let t = ts_type(inner, types);
        return if t.contains(' ') {
            format!("({t})[]")
        } else {
            format!("{t}[]")
        };
    }
    if let Some(inner) = rust
        .strip_prefix("Option<")
        .and_then(|r| r.strip_suffix('>'))
    {
        return ts_type(inner, types);
    }
    if let Some(n) = rust
        .strip_prefix("Exactly<")
        .and_then(|r| r.strip_suffix('>'))
    {
        return n.trim().to_string();
    }
    if let Some(inner) = rust.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
        if let Some((t, n)) = inner.rsplit_once(';') {
            let n: usize = n
                .trim()
                .parse()
                .unwrap_or_else(|_| panic!("build.rs: array length in `{rust}`"));
            return format!("[{}]", vec![ts_type(t, types); n].join(", "));
        }
    }
    match rust {
        "f64" | "f32" | "usize" | "u64" | "u32" | "u16" | "u8" | "i64" | "i32" => "number".into(),
        "bool" => "boolean".into(),
        "String" | "&str" | "&'static str" => "string".into(),
        "DVec3" => "[number, number, number]".into(),
        "Float32Array" | "Float64Array" | "Uint32Array" | "Uint8Array" => rust.into(),
        // The binding's input types (src/wasm/convert.rs).
        "Stride" => "3 | 4".into(),
        "Pose" => "Float64Array | Float32Array | number[] | { elements: ArrayLike<number> }".into(),
        "Positions" => "Float64Array | Float32Array | number[]".into(),
        _ => match types.0.get(rust) {
            Some(t) => t.clone(),
            None => panic!("build.rs: no TypeScript type for the Rust type `{rust}`"),
        },
    }
}

/// The interfaces, in order, as TypeScript declarations. `read` gives a
/// source file's text.
/// The TypeScript union of a Rust enum serialised as its variant names.
pub fn string_enum(file: &str, rust: &str) -> String {
    let (_, attrs, items) = parse(&read_source(file), "enum", rust, file);
    let rule = rename_all(&attrs);
    let union: Vec<String> = items
        .iter()
        .map(|v| format!("\"{}\"", rename(&v.line, rule)))
        .collect();
    union.join(" | ")
}

fn interfaces_ts(
    interfaces: &[Interface],
    enums: &[StringEnum],
    read: impl Fn(&str) -> String,
) -> String {
    let mut types = Types(HashMap::new());
    for e in enums {
        let (_, attrs, items) = parse(&read(e.file), "enum", e.rust, e.file);
        let rule = rename_all(&attrs);
        let union: Vec<String> = items
            .iter()
            .map(|v| format!("\"{}\"", rename(&v.line, rule)))
            .collect();
        types.0.insert(e.rust.into(), union.join(" | "));
    }
    for i in interfaces {
        types.0.insert(i.rust.into(), i.ts.into());
    }
    types.0.insert("Params".into(), "PipelineOptions".into());

    let mut out = String::new();
    for i in interfaces {
        let (doc, _, items) = parse(&read(i.file), "struct", i.rust, i.file);
        let mut extends = Vec::new();
        let mut body = String::new();
        for item in &items {
            let Some(field) = item.line.strip_prefix("pub ") else {
                continue;
            };
            let Some((name, ty)) = field.split_once(':') else {
                continue;
            };
            let (name, ty) = (name.trim(), ty.trim());
            if i.flatten.contains(&name) {
                extends.push(ts_type(ty, &types));
                continue;
            }
            // The JS objects' keys are camelCase (serde's `rename_all =
            // "camelCase"` on the serialised structs, by hand in the views),
            // or a field's own `#[serde(rename = "...")]`.
            let key = item
                .attrs
                .iter()
                .find_map(|a| a.split_once("rename = \"")?.1.split('"').next())
                .map_or_else(|| crate::shared::camel(name), str::to_string);
            let optional = i.optional || ty.starts_with("Option<");
            jsdoc(&mut body, "  ", &item.doc);
            body.push_str(&format!(
                "  {key}{}: {};\n",
                if optional { "?" } else { "" },
                ts_type(ty, &types)
            ));
        }
        out.push('\n');
        jsdoc(&mut out, "", &doc);
        let extends = if extends.is_empty() {
            String::new()
        } else {
            format!(" extends {}", extends.join(", "))
        };
        if body.is_empty() {
            out.push_str(&format!("export interface {}{extends} {{}}\n", i.ts));
        } else {
            out.push_str(&format!(
                "export interface {}{extends} {{\n{body}}}\n",
                i.ts
            ));
        }
    }
    out
}

/// Reads a source file for the generator, and tells cargo to rerun when it
/// changes.
fn read_source(file: &str) -> String {
    println!("cargo:rerun-if-changed={file}");
    fs::read_to_string(file).unwrap_or_else(|e| panic!("build.rs: cannot read {file}: {e}"))
}
