//! The crate's modules form no cycle: read from the `use` lines and the `crate::`/`super::`
//! paths of every source file (one module per file; `pub use` re-exports are followed, not
//! counted as uses; test modules are left out).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

type Module = Vec<String>;

/// Every module of `src/` (the library; `main.rs` is the binary) and its source.
fn modules() -> BTreeMap<Module, String> {
    fn walk(dir: &Path, root: &Path, out: &mut BTreeMap<Module, String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                walk(&p, root, out);
            } else if p.extension().is_some_and(|e| e == "rs") {
                let rel = p.strip_prefix(root).unwrap().with_extension("");
                let mut parts: Vec<String> = rel.iter().map(|c| c.to_string_lossy().into_owned()).collect();
                match parts.last().map(String::as_str) {
                    Some("main") if parts.len() == 1 => continue,
                    Some("lib") if parts.len() == 1 => parts.clear(),
                    Some("mod") => {
                        parts.pop();
                    }
                    _ => {}
                }
                out.insert(parts, std::fs::read_to_string(&p).unwrap());
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut out = BTreeMap::new();
    walk(&root, &root, &mut out);
    out
}

/// The source without comments, string contents and the `#[cfg(test)] mod tests` block.
fn code(source: &str) -> String {
    // the test module, whatever its cfg attribute
    let cut = source
        .find("\nmod tests {")
        .map(|at| source[..at].rfind("#[cfg(").filter(|&a| source[a..at].contains("test")).unwrap_or(at))
        .unwrap_or(source.len());
    let mut out = String::new();
    for line in source[..cut].lines() {
        let mut in_str = false;
        let mut prev = ' ';
        let mut kept = String::new();
        let chars: Vec<char> = line.chars().collect();
        let mut i = 0;
        while i < chars.len() {
            let c = chars[i];
            if !in_str && c == '/' && chars.get(i + 1) == Some(&'/') {
                break;
            }
            if c == '"' && prev != '\\' && prev != '\'' {
                in_str = !in_str;
                kept.push('"');
            } else if !in_str {
                kept.push(c);
            }
            prev = if prev == '\\' && c == '\\' { ' ' } else { c };
            i += 1;
        }
        out += &kept;
        out.push('\n');
    }
    out
}

/// The paths of `use` declarations: (public re-export?, path segments), trees expanded.
fn use_paths(code: &str) -> Vec<(bool, Vec<String>)> {
    fn expand(prefix: &[String], tree: &str, out: &mut Vec<(bool, Vec<String>)>, public: bool) {
        let tree = tree.trim();
        if tree.is_empty() {
            return;
        }
        if let Some(open) = tree.find('{') {
            let head: Vec<String> =
                tree[..open].split("::").map(str::trim).filter(|s| !s.is_empty()).map(String::from).collect();
            let body = &tree[open + 1..tree.rfind('}').unwrap()];
            let mut prefix = prefix.to_vec();
            prefix.extend(head);
            let (mut depth, mut start) = (0, 0);
            for (i, c) in body.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        expand(&prefix, &body[start..i], out, public);
                        start = i + 1;
                    }
                    _ => {}
                }
            }
            expand(&prefix, &body[start..], out, public);
        } else {
            let path = tree.split(" as ").next().unwrap();
            let mut full = prefix.to_vec();
            full.extend(path.split("::").map(str::trim).filter(|s| !s.is_empty()).map(String::from));
            out.push((public, full));
        }
    }
    let mut out = Vec::new();
    for statement in code.split(';') {
        let s = statement.trim_start();
        let Some(at) = find_use(s) else { continue };
        let public = s[..at].trim_end().ends_with(')') || s[..at].trim_end().ends_with("pub");
        expand(&[], &s[at + 4..], &mut out, public);
    }
    out
}

/// `code` without its `use` declarations.
fn without_uses(code: &str) -> String {
    code.split_inclusive(';').map(|chunk| find_use(chunk).map_or(chunk, |at| &chunk[..at])).collect()
}

/// Where a `use ` declaration starts in `statement` (after attributes and visibility).
fn find_use(statement: &str) -> Option<usize> {
    let mut offset = 0;
    for line in statement.lines() {
        let t = line.trim_start();
        let lead = line.len() - t.len();
        for prefix in ["use ", "pub use ", "pub(crate) use ", "pub(super) use "] {
            if t.starts_with(prefix) {
                return Some(offset + lead + prefix.len() - 4);
            }
        }
        offset += line.len() + 1;
    }
    None
}

/// The module a path names, following the re-exports of `exports` (module → name → child).
fn resolve(
    from: &Module,
    path: &[String],
    modules: &BTreeMap<Module, String>,
    exports: &BTreeMap<Module, BTreeMap<String, Module>>,
) -> Option<Module> {
    let (mut m, rest): (Module, &[String]) = match path.first().map(String::as_str) {
        Some("crate") => (Vec::new(), &path[1..]),
        Some("self") => (from.clone(), &path[1..]),
        Some("super") => {
            let mut m = from.clone();
            let mut k = 0;
            while path.get(k).map(String::as_str) == Some("super") {
                m.pop();
                k += 1;
            }
            (m, &path[k..])
        }
        Some(first) => {
            let mut child = from.clone();
            child.push(first.to_string());
            if !modules.contains_key(&child) {
                return None;
            }
            (from.clone(), path)
        }
        None => return None,
    };
    for seg in rest {
        let mut child = m.clone();
        child.push(seg.clone());
        if modules.contains_key(&child) {
            m = child;
        } else if let Some(target) = exports.get(&m).and_then(|e| e.get(seg)) {
            m = target.clone();
        } else {
            break;
        }
    }
    Some(m)
}

/// Every cycle through each module of `edges`, as "a → b → a" (one per start module reached
/// back).
fn find_cycles(edges: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<String> {
    let name = |m: &Module| if m.is_empty() { "crate".to_string() } else { m.join("::") };
    let mut cycles = Vec::new();
    for start in edges.keys() {
        let mut seen = BTreeSet::new();
        let mut stack: Vec<(Module, Vec<Module>)> = vec![(start.clone(), vec![start.clone()])];
        while let Some((v, trail)) = stack.pop() {
            for w in &edges[&v] {
                if w == start {
                    cycles.push(trail.iter().chain([start]).map(name).collect::<Vec<_>>().join(" → "));
                } else if seen.insert(w.clone()) && edges.contains_key(w) {
                    let mut t = trail.clone();
                    t.push(w.clone());
                    stack.push((w.clone(), t));
                }
            }
        }
    }
    cycles
}

#[test]
fn the_cycle_finder_finds_a_known_cycle() {
    let m = |s: &str| -> Module { s.split("::").map(String::from).collect() };
    let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    edges.insert(m("a"), [m("b")].into());
    edges.insert(m("b"), [m("c")].into());
    edges.insert(m("c"), BTreeSet::new());
    assert!(find_cycles(&edges).is_empty());
    edges.get_mut(&m("c")).unwrap().insert(m("a"));
    let cycles = find_cycles(&edges);
    assert!(cycles.contains(&"a → b → c → a".to_string()), "{cycles:?}");
}

#[test]
fn the_modules_form_no_cycle() {
    let modules = modules();
    let codes: BTreeMap<Module, String> = modules.iter().map(|(m, s)| (m.clone(), code(s))).collect();
    // re-exports: `pub use child::…::Name` in module m names `child` for `Name`
    let mut exports: BTreeMap<Module, BTreeMap<String, Module>> = BTreeMap::new();
    for (m, c) in &codes {
        for (public, path) in use_paths(c) {
            if !public || path.is_empty() {
                continue;
            }
            let first = if path[0] == "self" { path.get(1) } else { Some(&path[0]) };
            if let Some(first) = first {
                let mut child = m.clone();
                child.push(first.clone());
                if modules.contains_key(&child) {
                    exports.entry(m.clone()).or_default().insert(path.last().unwrap().clone(), child);
                }
            }
        }
    }
    let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (m, c) in &codes {
        let mut targets = BTreeSet::new();
        for (public, path) in use_paths(c) {
            // a re-export of a child is the parent's facade; any other path is a use
            let first = if path.first().map(String::as_str) == Some("self") { path.get(1) } else { path.first() };
            let of_child = first.is_some_and(|f| {
                let mut child = m.clone();
                child.push(f.clone());
                modules.contains_key(&child)
            });
            if !public || !of_child {
                targets.extend(resolve(m, &path, &modules, &exports));
            }
        }
        // paths written inline (`crate::linalg::Analyses::default()`)
        let c = &without_uses(c);
        let bytes = c.as_bytes();
        for start in ["crate::", "super::"] {
            let mut from = 0;
            while let Some(at) = c[from..].find(start) {
                let at = from + at;
                from = at + start.len();
                // inside a longer path (`super::super::x`): the whole path is read from its start
                if at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'_' || bytes[at - 1] == b':') {
                    continue;
                }
                let end = c[at..]
                    .find(|ch: char| !(ch.is_ascii_alphanumeric() || ch == '_' || ch == ':'))
                    .map_or(c.len(), |e| at + e);
                let path: Vec<String> = c[at..end].split("::").filter(|s| !s.is_empty()).map(String::from).collect();
                targets.extend(resolve(m, &path, &modules, &exports));
            }
        }
        // paths relative to a child module (`two_way::Symbolic`)
        let children: Vec<&Module> = modules.keys().filter(|k| k.len() == m.len() + 1 && k.starts_with(m)).collect();
        for child in children {
            let needle = format!("{}::", child.last().unwrap());
            let mut from = 0;
            while let Some(at) = c[from..].find(&needle) {
                let at = from + at;
                from = at + needle.len();
                let before = if at > 0 { bytes[at - 1] } else { b' ' };
                if !(before.is_ascii_alphanumeric() || before == b'_' || before == b':') {
                    targets.insert(child.clone());
                }
            }
        }
        targets.remove(m);
        edges.insert(m.clone(), targets);
    }
    let cycles = find_cycles(&edges);
    assert!(edges.len() > 50, "read {} modules", edges.len());
    assert!(cycles.is_empty(), "module cycles:\n{}", cycles.join("\n"));
}

#[test]
fn the_reader_sees_uses_and_reexports() {
    // the parser on a known text, so that the test above cannot pass by reading nothing
    let c =
        code("pub use a::{B, c::D};\nuse crate::x::{y, z::W}; // crate::q\nfn f() { crate::p::g(\"crate::s\"); }\n");
    let paths = use_paths(&c);
    assert!(paths.contains(&(true, vec!["a".into(), "B".into()])));
    assert!(paths.contains(&(true, vec!["a".into(), "c".into(), "D".into()])));
    assert!(paths.contains(&(false, vec!["crate".into(), "x".into(), "z".into(), "W".into()])));
    assert!(!c.contains("crate::q") && !c.contains("crate::s") && c.contains("crate::p::g"));
    let rest = without_uses(&c);
    assert!(!rest.contains("crate::x") && rest.contains("crate::p::g"), "{rest}");
}
