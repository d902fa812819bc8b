//! The crate's files import no one in a cycle, and the library's top-level
//! modules keep the layer order of the table in `src/lib.rs`.
//!
//! The graph is read from the source, independently of the compiler: every
//! `use` declaration (braces expanded) and every `crate::…` / `super::…` path
//! in the code of a file is an edge from that file to the file that defines
//! the item. A path through a module that re-exports the item (`pub use`) is
//! followed to the defining file, so a `mod.rs` that only re-exports its
//! children does not count as a dependency of those children. The bin crate
//! (`src/main.rs`, `src/cli/`) is read the same way; it reaches the library
//! only as `topple::…`, which never points back.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Cycles known today, each the sorted list of its files. Each one is to be
/// removed (never added to): the test fails on any cycle not listed here,
/// and on a listed one that no longer exists (so the list only shrinks).
const ALLOWED_CYCLES: &[&[&str]] = &[];

/// One file: its module path and the text of its code (comments removed).
struct File {
    module: Vec<String>,
    code: String,
}

/// What a module declares: child modules (name → module path of the file
/// or of a `#[path]` file), re-exports (name → absolute path) and globs.
#[derive(Default)]
struct Module {
    file: Option<PathBuf>,
    children: BTreeMap<String, Vec<String>>,
    reexports: BTreeMap<String, Vec<String>>,
    globs: Vec<Vec<String>>,
}

/// The code of a file without its comments, string contents and unit-test
/// module (`#[cfg(test)]` and all after it: the tests close each file).
fn strip_comments(src: &str) -> String {
    let src = src.find("#[cfg(test)]").map_or(src, |i| &src[..i]);
    let mut out = String::with_capacity(src.len());
    let b = src.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'/' && i + 1 < b.len() && b[i + 1] == b'/' {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i] == b'/' && i + 1 < b.len() && b[i + 1] == b'*' {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == b'/' && i + 1 < b.len() && b[i + 1] == b'*' {
                    depth += 1;
                    i += 2;
                } else if b[i] == b'*' && i + 1 < b.len() && b[i + 1] == b'/' {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if b[i] == b'"' {
            // string literal: skipped, so paths inside it are not edges
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else {
            let c = src[i..].chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// `use` trees expanded: `a::{b, c::{d, e as f}, *}` → [a::b, a::c::d, a::c::e, a::*].
fn expand_use(tree: &str) -> Vec<Vec<String>> {
    fn split_top(s: &str) -> Vec<&str> {
        let (mut depth, mut start, mut parts) = (0, 0, Vec::new());
        for (i, c) in s.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    parts.push(&s[start..i]);
                    start = i + 1;
                }
                _ => {}
            }
        }
        parts.push(&s[start..]);
        parts
            .into_iter()
            .map(str::trim)
            .filter(|p| !p.is_empty())
            .collect()
    }
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    let mut out = Vec::new();
    for part in split_top(&tree) {
        if let Some(open) = part.find('{') {
            let prefix: Vec<String> = part[..open]
                .trim_end_matches("::")
                .split("::")
                .filter(|s| !s.is_empty())
                .map(String::from)
                .collect();
            for sub in expand_use(&part[open + 1..part.len() - 1]) {
                let mut p = prefix.clone();
                if sub != ["self"] {
                    p.extend(sub);
                }
                out.push(p);
            }
        } else {
            let path = part.split(" as ").next().unwrap_or(part);
            let path = path.split("as").next().unwrap_or(path);
            out.push(path.split("::").map(String::from).collect());
        }
    }
    out
}

/// The `use` declarations of a file: (is `pub`, the expanded paths), and
/// the code with them removed.
/// A `use` declaration: whether it is a re-export, and its expanded paths.
type UseDecl = (bool, Vec<Vec<String>>);

fn use_decls(code: &str) -> (Vec<UseDecl>, String) {
    let mut decls = Vec::new();
    let mut rest = String::new();
    let mut i = 0;
    while let Some(k) = code[i..].find("use ") {
        let at = i + k;
        let before = code[..at].trim_end();
        let head_ok = before.is_empty()
            || before.ends_with(';')
            || before.ends_with('}')
            || before.ends_with('{')
            || before.ends_with(']')
            || before.ends_with("pub")
            || before.ends_with(')');
        let word_start = at == 0
            || !code.as_bytes()[at - 1].is_ascii_alphanumeric() && code.as_bytes()[at - 1] != b'_';
        if !(head_ok && word_start) {
            rest.push_str(&code[i..at + 4]);
            i = at + 4;
            continue;
        }
        let end = at + code[at..].find(';').unwrap();
        let is_pub = before.ends_with("pub")
            || before.ends_with("pub(crate)")
            || before.ends_with("pub(super)");
        decls.push((is_pub, expand_use(&code[at + 4..end])));
        rest.push_str(&code[i..at]);
        i = end + 1;
    }
    rest.push_str(&code[i..]);
    (decls, rest)
}

/// `crate::a::b` and `super::super::c` paths written inline in the code.
fn inline_paths(code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let b = code.as_bytes();
    for start in ["crate::", "super::", "self::"] {
        let mut i = 0;
        while let Some(k) = code[i..].find(start) {
            let at = i + k;
            i = at + start.len();
            if at > 0
                && (b[at - 1].is_ascii_alphanumeric() || b[at - 1] == b'_' || b[at - 1] == b':')
            {
                continue;
            }
            let mut end = at;
            while end < b.len()
                && (b[end].is_ascii_alphanumeric() || b[end] == b'_' || b[end] == b':')
            {
                end += 1;
            }
            let path: Vec<String> = code[at..end]
                .split("::")
                .filter(|s| !s.is_empty())
                .map(String::from)
                .collect();
            out.push(path);
        }
    }
    out
}

struct Crate {
    files: BTreeMap<PathBuf, File>,
    modules: BTreeMap<Vec<String>, Module>,
}

impl Crate {
    fn read(root: &Path, src: &Path) -> Crate {
        let mut c = Crate {
            files: BTreeMap::new(),
            modules: BTreeMap::new(),
        };
        c.add(root, src, Vec::new());
        c
    }

    /// Reads `file` as module `module` and, recursively, its `mod` children.
    fn add(&mut self, root: &Path, file: &Path, module: Vec<String>) {
        let text =
            std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let code = strip_comments(&text);
        let rel = file.strip_prefix(root).unwrap().to_path_buf();
        let dir = file.parent().unwrap();
        let own_dir = if file.file_name().unwrap() == "mod.rs"
            || file.file_name().unwrap() == "lib.rs"
            || file.file_name().unwrap() == "main.rs"
        {
            dir.to_path_buf()
        } else {
            dir.join(file.file_stem().unwrap())
        };
        // `#[path = "x.rs"] mod name;` and `mod name;` (not inline `mod name {`)
        let mut children = Vec::new();
        let mut pending_path: Option<String> = None;
        for line in text.lines() {
            let l = line.trim();
            if let Some(p) = l.strip_prefix("#[path = \"") {
                pending_path = Some(p.trim_end_matches("\"]").to_string());
                continue;
            }
            let decl = l
                .trim_start_matches("pub(crate) ")
                .trim_start_matches("pub(super) ")
                .trim_start_matches("pub ");
            if let Some(name) = decl.strip_prefix("mod ").and_then(|r| r.strip_suffix(';')) {
                let path = match pending_path.take() {
                    Some(p) => dir.join(p),
                    None if own_dir.join(format!("{name}.rs")).exists() => {
                        own_dir.join(format!("{name}.rs"))
                    }
                    None => own_dir.join(name).join("mod.rs"),
                };
                children.push((name.to_string(), path));
            } else if !l.starts_with("#[") {
                pending_path = None;
            }
        }
        let (decls, _) = use_decls(&code);
        let mut m = Module {
            file: Some(rel.clone()),
            ..Module::default()
        };
        for (is_pub, paths) in &decls {
            if !is_pub {
                continue;
            }
            for p in paths {
                let abs = absolute(&module, p);
                if p.last().map(String::as_str) == Some("*") {
                    m.globs.push(abs[..abs.len() - 1].to_vec());
                } else if let Some(name) = p.last() {
                    m.reexports.insert(name.clone(), abs);
                }
            }
        }
        for (name, path) in &children {
            let mut child = module.clone();
            child.push(name.clone());
            m.children.insert(name.clone(), child);
            let _ = path;
        }
        self.modules.insert(module.clone(), m);
        self.files.insert(
            rel,
            File {
                module: module.clone(),
                code,
            },
        );
        for (name, path) in children {
            let mut child = module.clone();
            child.push(name);
            self.add(root, &path, child);
        }
    }

    /// The file that defines `path` (absolute, from the crate root), through
    /// re-exports; `None` for paths outside the crate.
    fn resolve(&self, path: &[String], depth: usize) -> Option<PathBuf> {
        if depth > 16 {
            return None;
        }
        // the deepest module on the path
        let mut k = 0;
        while k < path.len() && self.modules.contains_key(&path[..=k]) {
            k += 1;
        }
        if k == 0 {
            return self.modules.get(&Vec::new()).and_then(|root| {
                let name = path.first()?;
                if let Some(target) = root.reexports.get(name) {
                    if target.len() == 1 {
                        return None; // an external crate re-exported
                    }
                    let mut t = target.clone();
                    t.extend_from_slice(&path[1..]);
                    return self.resolve(&t, depth + 1);
                }
                root.file.clone()
            });
        }
        let module = &self.modules[&path[..k]];
        if k < path.len() {
            let name = &path[k];
            if let Some(target) = module.reexports.get(name) {
                let mut t = target.clone();
                t.extend_from_slice(&path[k + 1..]);
                return self.resolve(&t, depth + 1).or(module.file.clone());
            }
            for g in &module.globs {
                let mut t = g.clone();
                t.extend_from_slice(&path[k..]);
                if let Some(f) = self.resolve(&t, depth + 1)
                    && self.files[&f].module != path[..k]
                {
                    return Some(f);
                }
            }
        }
        module.file.clone()
    }
}

/// `crate::a`, `super::a`, `self::a`, `a` (a child of the current module)
/// made absolute from the crate root; external crates keep their name.
fn absolute(module: &[String], p: &[String]) -> Vec<String> {
    let mut base = module.to_vec();
    let mut i = 0;
    match p.first().map(String::as_str) {
        Some("crate") => {
            base.clear();
            i = 1;
        }
        Some("self") => i = 1,
        Some("super") => {
            while p.get(i).map(String::as_str) == Some("super") {
                base.pop();
                i += 1;
            }
        }
        _ => {}
    }
    base.extend_from_slice(&p[i..]);
    base
}

/// Edges file → file of one crate (self-edges dropped).
fn edges(c: &Crate) -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
    let mut g: BTreeMap<PathBuf, BTreeSet<PathBuf>> = BTreeMap::new();
    for (path, f) in &c.files {
        let (decls, rest) = use_decls(&f.code);
        let mut refs: Vec<Vec<String>> = Vec::new();
        for (is_pub, paths) in decls {
            if is_pub {
                continue; // a re-export: followed when a path goes through it
            }
            for p in paths {
                let first = p.first().map(String::as_str).unwrap_or("");
                let local = matches!(first, "crate" | "super" | "self")
                    || c.modules[&f.module].children.contains_key(first);
                if local {
                    refs.push(absolute(&f.module, &p));
                }
            }
        }
        for p in inline_paths(&rest) {
            refs.push(absolute(&f.module, &p));
        }
        let out = g.entry(path.clone()).or_default();
        for r in refs {
            if r.iter().any(|s| s.starts_with('$')) {
                continue; // a path built inside a macro: not resolved
            }
            let r: Vec<String> = r.into_iter().filter(|s| s != "*").collect();
            if let Some(target) = c.resolve(&r, 0)
                && &target != path
            {
                out.insert(target);
            }
        }
    }
    g
}

/// The strongly connected components with more than one file (Tarjan).
fn cycles(g: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<Vec<String>> {
    struct T<'a> {
        g: &'a BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        index: BTreeMap<&'a PathBuf, usize>,
        low: BTreeMap<&'a PathBuf, usize>,
        stack: Vec<&'a PathBuf>,
        on: BTreeSet<&'a PathBuf>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a PathBuf) {
        let n = t.index.len();
        t.index.insert(v, n);
        t.low.insert(v, n);
        t.stack.push(v);
        t.on.insert(v);
        if let Some(next) = t.g.get(v) {
            for w in next {
                let Some((w, _)) = t.g.get_key_value(w) else {
                    continue;
                };
                if !t.index.contains_key(w) {
                    visit(t, w);
                    let lw = t.low[w];
                    let lv = t.low.get_mut(v).unwrap();
                    *lv = (*lv).min(lw);
                } else if t.on.contains(w) {
                    let iw = t.index[w];
                    let lv = t.low.get_mut(v).unwrap();
                    *lv = (*lv).min(iw);
                }
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = t.stack.pop().unwrap();
                t.on.remove(w);
                comp.push(format!("src/{}", w.display()));
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t = T {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in g.keys() {
        if !t.index.contains_key(v) {
            visit(&mut t, v);
        }
    }
    t.out.sort();
    t.out
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn all_cycles() -> Vec<Vec<String>> {
    let root = src();
    let mut found = cycles(&edges(&Crate::read(&root, &root.join("lib.rs"))));
    found.extend(cycles(&edges(&Crate::read(&root, &root.join("main.rs")))));
    found.sort();
    found
}

#[test]
fn no_import_cycles_between_files_but_the_listed_ones() {
    let found = all_cycles();
    let allowed: Vec<Vec<String>> = ALLOWED_CYCLES
        .iter()
        .map(|c| c.iter().map(|s| s.to_string()).collect())
        .collect();
    let new: Vec<_> = found.iter().filter(|c| !allowed.contains(c)).collect();
    assert!(
        new.is_empty(),
        "files that import each other in a cycle: {new:#?}"
    );
    let gone: Vec<_> = allowed.iter().filter(|c| !found.contains(c)).collect();
    assert!(
        gone.is_empty(),
        "listed in ALLOWED_CYCLES but no longer a cycle (remove them from the list): {gone:#?}"
    );
}

/// The layer order of the table in `src/lib.rs`: each top-level module in
/// the order of its row.
fn lib_layers() -> Vec<String> {
    let text = std::fs::read_to_string(src().join("lib.rs")).unwrap();
    text.lines()
        .filter_map(|l| l.strip_prefix("//! | [`"))
        .map(|l| l[..l.find('`').unwrap()].to_string())
        .collect()
}

#[test]
fn top_level_modules_use_only_the_layers_above_them() {
    let root = src();
    let krate = Crate::read(&root, &root.join("lib.rs"));
    let layers = lib_layers();
    assert!(
        layers.len() >= 8,
        "the layer table of src/lib.rs: {layers:?}"
    );
    let rank = |file: &Path| -> Option<(String, usize)> {
        let top = krate.files[file].module.first()?.clone();
        let i = layers.iter().position(|l| *l == top)?;
        Some((top, i))
    };
    // every top-level module of the library but the private helpers (`par`,
    // rayon or its stand-in; `clock`, the CPU time of a thread) and the
    // Bevy plugin (the top layer, which may use all others) is in the table
    for m in krate.modules[&Vec::new()].children.keys() {
        assert!(
            layers.contains(m) || ["bevy", "par", "clock"].contains(&m.as_str()),
            "top-level module {m} is missing from the layer table of src/lib.rs"
        );
    }
    let mut wrong = Vec::new();
    for (from, to) in edges(&krate) {
        let Some((a, ia)) = rank(&from) else { continue };
        for t in to {
            if let Some((b, ib)) = rank(&t)
                && ib > ia
            {
                wrong.push(format!(
                    "{} ({a}) uses {} ({b})",
                    from.display(),
                    t.display()
                ));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "uses of a layer below (src/lib.rs table order {layers:?}):\n{}",
        wrong.join("\n")
    );
}

/// Code behind a cargo feature uses only what that feature turns on: the
/// Bevy plugin (`bevy`, which turns on `f32` only) never the f64 build, the
/// stress sweep (both builds) or anything else behind `f64`, so a game's
/// `default-features = false, features = ["bevy"]` compiles.
#[test]
fn the_bevy_plugin_uses_only_what_its_feature_turns_on() {
    let root = src();
    let krate = Crate::read(&root, &root.join("lib.rs"));
    let mut wrong = Vec::new();
    let mut read = 0;
    for (path, f) in &krate.files {
        if !path.starts_with("bevy") {
            continue;
        }
        read += 1;
        for name in [
            "rapier::f64",
            "rapier2d_f64",
            "stress::",
            "rayon::",
            "par::",
        ] {
            if f.code.contains(name) {
                wrong.push(format!("{} names {name}", path.display()));
            }
        }
    }
    assert!(read >= 5, "src/bevy/ not read");
    assert!(
        wrong.is_empty(),
        "the Bevy plugin needs more than `f32`:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn the_reader_sees_a_cycle_it_is_given() {
    // two throw-away files that import each other, read like src/
    let dir = std::env::temp_dir().join(format!("topple-module-graph-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("lib.rs"), "mod a;\nmod b;\npub use a::A;\n").unwrap();
    std::fs::write(
        dir.join("a.rs"),
        "use crate::b::{B, other::{C}};\npub struct A;\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("b.rs"),
        "pub struct B;\npub mod other { pub struct C; }\nfn f() -> super::A { crate::A }\n",
    )
    .unwrap();
    let found = cycles(&edges(&Crate::read(&dir, &dir.join("lib.rs"))));
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(
        found,
        vec![vec!["src/a.rs".to_string(), "src/b.rs".to_string()]]
    );
}
/// Prints the library's file graph:
/// `cargo test --test module_graph -- --ignored --nocapture`.
#[test]
#[ignore]
fn dump_edges() {
    let root = src();
    for (f, to) in edges(&Crate::read(&root, &root.join("lib.rs"))) {
        for t in to {
            println!("{} -> {}", f.display(), t.display());
        }
    }
}
