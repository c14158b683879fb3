//! The module graph has no import circles: no module of `src/` refers to a
//! module that refers back to it, directly or around a longer loop.
//!
//! The rules, as this test applies them:
//!
//! - Every `src/**/*.rs` but `src/bin/` (other crates) is a module:
//!   `src/lib.rs` is the crate root, `src/geometry/hull.rs` is
//!   `geometry::hull`, `src/sim/mod.rs` is `sim`.
//! - A module refers to another through `use crate::...`, `use super::...`
//!   and `use self::...` items (use trees with braces are expanded) and
//!   through `crate::`, `super::` and `self::` paths in code. Comments,
//!   doc comments (and so intra-doc links) and string literals are not
//!   read.
//! - A path resolves to the longest prefix of it that is a module file;
//!   when the segment after that prefix is a name the module re-exports
//!   (`pub use x::Name`), it resolves on through the re-export to the module
//!   that defines the name (`crate::geometry::Polygon3` is a reference to
//!   `geometry::polygon`).
//! - The parent/child relation that `mod x;` creates is not an edge, and
//!   neither is a module's use of its own children through relative paths
//!   (`pub use x::Name`, `x::f()` in a `mod.rs`): that is how a module
//!   exposes its children. A child's reference to its parent
//!   (`super::Name` of an item defined in the parent's own file) is an
//!   edge, like any other.
//! - Test code is skipped: items under `#[cfg(test)]` (the `mod tests { }`
//!   blocks at the ends of files) and the files of `#[cfg(test)] mod x;`.
//!   Inline modules (`mod x86 { }`) belong to their file's module.
//!
//! - Circles are looked for between module files, and then between the
//!   modules one level up (and so on to the top-level modules), where a
//!   module stands for itself and all its submodules: `detect` referring to
//!   `scenario::merge` while `scenario` refers to `detect` is a circle of
//!   `detect` and `scenario`, though `scenario::merge` itself does not
//!   refer to `detect`.
//!
//! The test fails listing every circle (each strongly connected group of
//! modules, with the pairs in it that refer to each other directly and the
//! references that make each edge).

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// A module path: `[]` for the crate root, `["geometry", "hull"]`.
type ModPath = Vec<String>;

fn show(m: &ModPath) -> String {
    if m.is_empty() {
        "crate".to_string()
    } else {
        m.join("::")
    }
}

/// Every `.rs` file under `dir`, recursively.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The module path of a file relative to `src/`.
fn module_of(rel: &Path) -> ModPath {
    let mut parts: Vec<String> = rel
        .iter()
        .map(|s| s.to_string_lossy().into_owned())
        .collect();
    let file = parts.pop().unwrap();
    match file.as_str() {
        "lib.rs" | "mod.rs" => {}
        f => parts.push(f.trim_end_matches(".rs").to_string()),
    }
    parts
}

/// The source without comments, string and char literals (replaced by
/// blanks, so that nothing in them is read as a path).
fn strip(src: &str) -> String {
    let b: Vec<char> = src.chars().collect();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < b.len() && b[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push(' ');
        } else if c == 'r' && (next == Some('"') || next == Some('#')) && !ident_before(&b, i) {
            // Raw string r"..." or r#"..."#.
            let mut j = i + 1;
            let mut hashes = 0;
            while b.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&'"') {
                out.push(c);
                i += 1;
                continue;
            }
            j += 1;
            loop {
                if j >= b.len() {
                    break;
                }
                if b[j] == '"' && (0..hashes).all(|k| b.get(j + 1 + k) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            i = j;
            out.push_str("\"\"");
        } else if c == '"' {
            i += 1;
            while i < b.len() && b[i] != '"' {
                if b[i] == '\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if c == '\'' {
            // A char literal ('a', '\n', '\u{..}') or a lifetime ('a).
            if next == Some('\\') {
                let mut j = i + 2;
                while j < b.len() && b[j] != '\'' {
                    j += 1;
                }
                i = j + 1;
                out.push_str("' '");
            } else if b.get(i + 2) == Some(&'\'') {
                i += 3;
                out.push_str("' '");
            } else {
                out.push(c);
                i += 1;
            }
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

fn ident_before(b: &[char], i: usize) -> bool {
    i > 0 && (b[i - 1].is_alphanumeric() || b[i - 1] == '_')
}

/// Identifiers, `::` and single punctuation characters.
fn tokens(src: &str) -> Vec<String> {
    let b: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_alphanumeric() || c == '_' {
            let s = i;
            while i < b.len() && (b[i].is_alphanumeric() || b[i] == '_') {
                i += 1;
            }
            out.push(b[s..i].iter().collect());
        } else if c == ':' && b.get(i + 1) == Some(&':') {
            out.push("::".into());
            i += 2;
        } else if c.is_whitespace() {
            i += 1;
        } else {
            out.push(c.to_string());
            i += 1;
        }
    }
    out
}

/// The paths of a use tree starting at `t[*i]`, up to (not including) the
/// `;`, `,` or `}` that ends it. `a::{b, c::d}` gives `a::b` and `a::c::d`;
/// `a::{self}` gives `a`; `a::*` gives `a`; `a as b` gives `a` (with the
/// alias as the name it is known by).
fn use_tree(t: &[String], i: &mut usize, prefix: &[String], out: &mut Vec<(ModPath, String)>) {
    let mut path = prefix.to_vec();
    loop {
        let Some(tok) = t.get(*i) else { return };
        match tok.as_str() {
            "{" => {
                *i += 1;
                loop {
                    if t.get(*i).map(String::as_str) == Some("}") {
                        *i += 1;
                        break;
                    }
                    use_tree(t, i, &path, out);
                    match t.get(*i).map(String::as_str) {
                        Some(",") => *i += 1,
                        Some("}") => {
                            *i += 1;
                            break;
                        }
                        _ => return,
                    }
                }
                return;
            }
            "*" => {
                *i += 1;
                out.push((path, "*".into()));
                return;
            }
            "::" => *i += 1,
            ";" | "," | "}" => {
                let name = path.last().cloned().unwrap_or_default();
                if path.last().map(String::as_str) == Some("self") {
                    path.pop();
                }
                let name = if name == "self" {
                    path.last().cloned().unwrap_or_default()
                } else {
                    name
                };
                out.push((path, name));
                return;
            }
            "as" => {
                let alias = t.get(*i + 1).cloned().unwrap_or_default();
                *i += 2;
                if path.last().map(String::as_str) == Some("self") {
                    path.pop();
                }
                out.push((path, alias));
                return;
            }
            _ => {
                path.push(tok.clone());
                *i += 1;
            }
        }
    }
}

/// One use item or path in code, as written.
struct Reference {
    /// The module (file module plus inline modules) it is written in.
    scope: ModPath,
    /// The path, starting with `crate`, `super`, `self` or a plain name.
    path: ModPath,
    /// `pub use` (any visibility): a re-export, with the name it exports.
    reexport: Option<String>,
    /// A `use` item (not a path in code).
    is_use: bool,
}

/// The references of one file, and the names of its `#[cfg(test)] mod x;`
/// children.
fn scan(module: &ModPath, src: &str) -> (Vec<Reference>, Vec<String>) {
    let t = tokens(&strip(src));
    let mut refs = Vec::new();
    let mut test_children = Vec::new();
    // Inline modules open: (name, brace depth inside them).
    let mut inline: Vec<(String, usize)> = Vec::new();
    let mut depth = 0usize;
    let mut i = 0;
    let scope = |inline: &Vec<(String, usize)>| {
        let mut s = module.clone();
        s.extend(inline.iter().map(|(n, _)| n.clone()));
        s
    };
    while i < t.len() {
        let tok = t[i].as_str();
        // #[cfg(test)]: skip the item it is on.
        if tok == "#"
            && t[i + 1..].starts_with(&["[", "cfg", "(", "test", ")", "]"].map(String::from))
        {
            i += 7;
            // Further attributes.
            while t.get(i).map(String::as_str) == Some("#") {
                let mut d = 0;
                i += 1;
                while i < t.len() {
                    match t[i].as_str() {
                        "[" => d += 1,
                        "]" => {
                            d -= 1;
                            if d == 0 {
                                i += 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                    i += 1;
                }
            }
            // `mod x;` names a test-only file.
            if t.get(i).map(String::as_str) == Some("mod")
                && t.get(i + 2).map(String::as_str) == Some(";")
            {
                test_children.push(t[i + 1].clone());
            }
            // Up to the item's `;` or through its `{ }` block.
            while i < t.len() && t[i] != ";" && t[i] != "{" {
                i += 1;
            }
            if t.get(i).map(String::as_str) == Some("{") {
                let mut d = 0;
                while i < t.len() {
                    match t[i].as_str() {
                        "{" => d += 1,
                        "}" => {
                            d -= 1;
                            if d == 0 {
                                break;
                            }
                        }
                        _ => {}
                    }
                    i += 1;
                }
            }
            i += 1;
            continue;
        }
        match tok {
            "mod" if t.get(i + 2).map(String::as_str) == Some("{") => {
                inline.push((t[i + 1].clone(), depth + 1));
                depth += 1;
                i += 3;
                continue;
            }
            "{" => depth += 1,
            "}" => {
                if inline.last().is_some_and(|&(_, d)| d == depth) {
                    inline.pop();
                }
                depth = depth.saturating_sub(1);
            }
            "use" => {
                // Visibility before it: `pub`, `pub(crate)`, `pub(super)`, ...
                let public = (i >= 1 && t[i - 1] == "pub")
                    || (i >= 4 && t[i - 1] == ")" && t[i - 4] == "pub");
                let mut j = i + 1;
                if t.get(j).map(String::as_str) == Some("::") {
                    j += 1; // `use ::extern_crate::...`
                }
                let mut items = Vec::new();
                use_tree(&t, &mut j, &[], &mut items);
                for (path, name) in items {
                    refs.push(Reference {
                        scope: scope(&inline),
                        path,
                        reexport: public.then_some(name),
                        is_use: true,
                    });
                }
                while j < t.len() && t[j] != ";" {
                    j += 1;
                }
                i = j + 1;
                continue;
            }
            "crate" | "super" | "self"
                if t.get(i + 1).map(String::as_str) == Some("::")
                    && !(i >= 1 && (t[i - 1] == "::" || t[i - 1] == "$")) =>
            {
                let mut path = vec![t[i].clone()];
                let mut j = i + 1;
                while t.get(j).map(String::as_str) == Some("::")
                    && t.get(j + 1)
                        .is_some_and(|s| s.chars().all(|c| c.is_alphanumeric() || c == '_'))
                {
                    path.push(t[j + 1].clone());
                    j += 2;
                }
                refs.push(Reference {
                    scope: scope(&inline),
                    path,
                    reexport: None,
                    is_use: false,
                });
                i = j;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    (refs, test_children)
}

struct Crate {
    /// Module files.
    modules: BTreeSet<ModPath>,
    /// Re-exports: module -> exported name -> (scope written in, path).
    reexports: BTreeMap<ModPath, BTreeMap<String, (ModPath, ModPath)>>,
}

impl Crate {
    /// The absolute path of `path` written in `scope`, or `None` for a path
    /// into another crate (or a relative one that names no child module).
    fn absolute(&self, scope: &ModPath, path: &ModPath) -> Option<ModPath> {
        let mut segs = path.iter().peekable();
        let mut base: ModPath = match segs.peek().map(|s| s.as_str()) {
            Some("crate") => {
                segs.next();
                Vec::new()
            }
            Some("self") => {
                segs.next();
                scope.clone()
            }
            Some("super") => {
                let mut b = scope.clone();
                while segs.peek().map(|s| s.as_str()) == Some("super") {
                    segs.next();
                    b.pop()?;
                }
                b
            }
            Some(first) => {
                // Relative: a child module of the scope, or another crate.
                let mut child = scope.clone();
                child.push(first.to_string());
                if !self.modules.contains(&child) {
                    return None;
                }
                scope.clone()
            }
            None => return None,
        };
        base.extend(segs.cloned());
        Some(base)
    }

    /// The module file an absolute path refers to: the longest module
    /// prefix, followed through re-exports of the next segment.
    fn resolve(&self, abs: &ModPath, hops: usize) -> ModPath {
        let n = (0..=abs.len())
            .rev()
            .find(|&n| self.modules.contains(&abs[..n]))
            .unwrap_or(0);
        let module = abs[..n].to_vec();
        if hops < 8 {
            if let Some(name) = abs.get(n) {
                if let Some((scope, path)) = self.reexports.get(&module).and_then(|m| m.get(name)) {
                    if let Some(target) = self.absolute(scope, path) {
                        let mut target = target;
                        target.extend(abs[n + 1..].iter().cloned());
                        return self.resolve(&target, hops + 1);
                    }
                }
            }
        }
        module
    }
}

/// Strongly connected components with more than one module (Tarjan).
fn circles(edges: &BTreeMap<ModPath, BTreeSet<ModPath>>) -> Vec<Vec<ModPath>> {
    struct State<'a> {
        edges: &'a BTreeMap<ModPath, BTreeSet<ModPath>>,
        index: BTreeMap<ModPath, usize>,
        low: BTreeMap<ModPath, usize>,
        stack: Vec<ModPath>,
        on_stack: BTreeSet<ModPath>,
        next: usize,
        out: Vec<Vec<ModPath>>,
    }
    fn visit(s: &mut State, v: &ModPath) {
        s.index.insert(v.clone(), s.next);
        s.low.insert(v.clone(), s.next);
        s.next += 1;
        s.stack.push(v.clone());
        s.on_stack.insert(v.clone());
        let targets: Vec<ModPath> = s.edges.get(v).into_iter().flatten().cloned().collect();
        for w in &targets {
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.on_stack.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut group = Vec::new();
            loop {
                let w = s.stack.pop().unwrap();
                s.on_stack.remove(&w);
                let done = &w == v;
                group.push(w);
                if done {
                    break;
                }
            }
            if group.len() > 1 {
                group.sort();
                s.out.push(group);
            }
        }
    }
    let mut s = State {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    let nodes: Vec<ModPath> = edges.keys().cloned().collect();
    for v in &nodes {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.out.sort();
    s.out
}

/// Module -> referenced module -> the references (as written) that make the
/// edge.
type Graph = BTreeMap<ModPath, BTreeMap<ModPath, BTreeSet<String>>>;

/// The reference graph of the crate in `src`.
fn graph(src: &Path) -> Graph {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut scanned = Vec::new();
    let mut test_files = BTreeSet::new();
    for f in files {
        let rel = f.strip_prefix(src).unwrap().to_path_buf();
        if rel.starts_with("bin") || rel == Path::new("main.rs") {
            continue;
        }
        let module = module_of(&rel);
        let text = fs::read_to_string(&f).unwrap();
        let (refs, test_children) = scan(&module, &text);
        for c in test_children {
            let mut m = module.clone();
            m.push(c);
            test_files.insert(m);
        }
        scanned.push((module, refs));
    }
    // Files of test-only modules, and everything below them, are skipped.
    scanned.retain(|(m, _)| !(1..=m.len()).any(|n| test_files.contains(&m[..n])));
    let mut krate = Crate {
        modules: scanned.iter().map(|(m, _)| m.clone()).collect(),
        reexports: BTreeMap::new(),
    };
    for (module, refs) in &scanned {
        for r in refs {
            if let Some(name) = &r.reexport {
                if name != "*" && !name.is_empty() {
                    krate
                        .reexports
                        .entry(module.clone())
                        .or_default()
                        .insert(name.clone(), (r.scope.clone(), r.path.clone()));
                }
            }
        }
    }
    let mut g: Graph = BTreeMap::new();
    for (module, refs) in &scanned {
        g.entry(module.clone()).or_default();
        for r in refs {
            // Relative paths (a module's own children, other crates) are
            // not edges; only crate::, super:: and self:: paths are.
            if !matches!(
                r.path.first().map(String::as_str),
                Some("crate" | "super" | "self")
            ) {
                continue;
            }
            let Some(abs) = krate.absolute(&r.scope, &r.path) else {
                continue;
            };
            let target = krate.resolve(&abs, 0);
            if &target == module {
                continue;
            }
            let how = format!(
                "{}{}",
                if r.is_use { "use " } else { "" },
                r.path.join("::")
            );
            g.entry(module.clone())
                .or_default()
                .entry(target)
                .or_default()
                .insert(how);
        }
    }
    g
}

/// A readable list of the circles of `g`, empty if there are none.
fn report(g: &Graph) -> String {
    let edges: BTreeMap<ModPath, BTreeSet<ModPath>> = g
        .iter()
        .map(|(m, ts)| (m.clone(), ts.keys().cloned().collect()))
        .collect();
    let mut text = String::new();
    for group in circles(&edges) {
        let members: BTreeSet<&ModPath> = group.iter().collect();
        text.push_str(&format!(
            "circle of {} modules: {}\n",
            group.len(),
            group.iter().map(show).collect::<Vec<_>>().join(", ")
        ));
        for a in &group {
            for (b, how) in &g[a] {
                if !members.contains(b) {
                    continue;
                }
                let mutual = edges.get(b).is_some_and(|t| t.contains(a));
                text.push_str(&format!(
                    "  {} -> {}{}: {}\n",
                    show(a),
                    show(b),
                    if mutual { " (mutual)" } else { "" },
                    how.iter().cloned().collect::<Vec<_>>().join("; ")
                ));
            }
        }
    }
    text
}

/// The graph of the modules at `depth` (their paths cut after `depth`
/// segments): `detect` and `scenario` for `detect::ransac` and
/// `scenario::merge` at depth 1. Edges inside one cut module vanish; the
/// references keep the file they are written in.
fn collapse(g: &Graph, depth: usize) -> Graph {
    let mut out: Graph = BTreeMap::new();
    for (a, targets) in g {
        let ca = a[..a.len().min(depth)].to_vec();
        out.entry(ca.clone()).or_default();
        for (b, how) in targets {
            let cb = b[..b.len().min(depth)].to_vec();
            // Not between a module and its own ancestor or descendant.
            if ca.starts_with(&cb) || cb.starts_with(&ca) {
                continue;
            }
            let refs = out.entry(ca.clone()).or_default().entry(cb).or_default();
            refs.extend(how.iter().map(|h| format!("{} in {}", h, show(a))));
        }
    }
    out
}

/// Circles between module files, then between the modules they are parts
/// of (`detect` -> `scenario::merge` and `scenario` -> `detect` make a
/// circle of `detect` and `scenario`).
fn full_report(g: &Graph) -> String {
    let mut text = report(g);
    let deepest = g.keys().map(Vec::len).max().unwrap_or(0);
    for depth in (1..deepest).rev() {
        let coarse = report(&collapse(g, depth));
        if !coarse.is_empty() {
            text.push_str(&format!(
                "between the modules {depth} level(s) below the crate, \
                 counting what their submodules refer to:\n{coarse}"
            ));
        }
    }
    text
}

#[test]
fn no_import_circles() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let g = graph(&src);
    assert!(
        g.len() > 10,
        "found only {} modules in {}",
        g.len(),
        src.display()
    );
    let text = full_report(&g);
    assert!(
        text.is_empty(),
        "modules that refer to each other, directly or around a loop:\n{text}"
    );
}

/// The scanner itself, on a made-up crate: it finds a circle through a
/// re-export, a `super::` path in code and an inline module, and ignores
/// comments, strings, test code and a parent's use of its children.
#[test]
fn finds_circles_in_a_made_up_crate() {
    let dir = std::env::temp_dir().join(format!("polyscene-arch-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    let files = [
        (
            "lib.rs",
            "pub mod a;\npub mod b;\npub mod c;\npub use a::Thing;\n",
        ),
        (
            "a/mod.rs",
            "mod x;\nmod y;\n#[cfg(test)]\nmod tests;\npub use x::Thing;\npub fn f() { y::g(); }\n",
        ),
        ("a/x.rs", "use crate::b::B;\npub struct Thing;\n"),
        ("a/y.rs", "pub fn g() { super::x::Thing; }\n"),
        ("a/tests.rs", "use crate::c::C;\n"),
        (
            "b.rs",
            "// use crate::c::C;\n/// [`C`](crate::c::C)\npub struct B;\n\
             const S: &str = \"crate::c::C\";\n\
             fn h() -> crate::Thing { crate::Thing }\n\
             #[cfg(test)]\nmod tests { use crate::c::C; }\n",
        ),
        (
            "c.rs",
            "pub struct C;\nmod inner { use super::C; fn k() { crate::a::f(); } }\n",
        ),
    ];
    for (name, text) in files {
        let p = dir.join(name);
        fs::create_dir_all(p.parent().unwrap()).unwrap();
        fs::write(p, text).unwrap();
    }
    let g = graph(&dir);
    let edges = |m: &str| -> Vec<String> {
        let key: ModPath = if m == "crate" {
            Vec::new()
        } else {
            m.split("::").map(String::from).collect()
        };
        g[&key].keys().map(show).collect()
    };
    assert_eq!(edges("a::x"), ["b"]);
    assert_eq!(edges("a::y"), ["a::x"]);
    // `crate::Thing` goes through two re-exports to `a::x`.
    assert_eq!(edges("b"), ["a::x"]);
    // The parent's use of its children is not an edge; test code is skipped.
    assert!(edges("a").is_empty());
    assert!(!g.contains_key(&vec!["a".to_string(), "tests".to_string()]));
    assert_eq!(edges("c"), ["a"]);
    let text = report(&g);
    assert!(text.contains("circle of 2 modules: a::x, b\n"), "{text}");
    assert!(
        text.contains("a::x -> b (mutual): use crate::b::B"),
        "{text}"
    );
    // At the top level, c -> a (from c) and a -> b (from a::x) make no
    // circle; a and b do.
    let top = report(&collapse(&g, 1));
    assert!(top.contains("circle of 2 modules: a, b\n"), "{top}");
    assert!(
        top.contains("a -> b (mutual): use crate::b::B in a::x"),
        "{top}"
    );
    let _ = fs::remove_dir_all(&dir);
}
