//! The layers of docs/architecture.md, held by the code: every `crate::`, `super::` and `self::`
//! path in src/ (a `use` tree or a path written inline, outside comments, strings and
//! `#[cfg(test)]` modules) is resolved to the file that defines it, through the `pub use`
//! faces of the modules on the way, and
//! - no file may use a file of a higher layer than its own (the layer of a file is that of
//!   its top-level module, as the table in docs/architecture.md gives it), and
//! - no files may use each other in a cycle.
//!
//! Every top-level module must be in the table. The table is parsed from docs/architecture.md
//! itself, so that the document and the check cannot disagree.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The layers, lowest first: each a list of top-level module names.
fn layer_table() -> Vec<(String, Vec<String>)> {
    let text = std::fs::read_to_string(root().join("docs/architecture.md")).unwrap();
    let start = text
        .find("## Layers")
        .expect("docs/architecture.md has a '## Layers' section");
    let mut layers = Vec::new();
    for line in text[start..].lines().skip(1) {
        let line = line.trim();
        if line.starts_with("##") {
            break;
        }
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() < 4 || cells[1] == "layer" || cells[1].starts_with("---") {
            continue;
        }
        let modules: Vec<String> = cells[2]
            .split('`')
            .skip(1)
            .step_by(2)
            .map(|m| m.trim_end_matches('/').to_string())
            .collect();
        layers.push((cells[1].to_string(), modules));
    }
    assert!(
        layers.len() >= 3,
        "docs/architecture.md's layer table not found"
    );
    layers
}

/// Every .rs file under src/ except the binary, as its path relative to src/.
fn source_files(dir: &Path, out: &mut Vec<String>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            source_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let rel = path.strip_prefix(root().join("src")).unwrap();
            let rel = rel.to_string_lossy().replace('\\', "/");
            if !rel.starts_with("bin/") {
                out.push(rel);
            }
        }
    }
}

/// The module path of a file (`local/plan.rs` -> [local, plan]; `lib.rs` -> []).
fn module_of(file: &str) -> Vec<String> {
    let mut parts: Vec<String> = file
        .trim_end_matches(".rs")
        .split('/')
        .map(String::from)
        .collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

/// The file that holds module `path`, if any.
fn module_file(path: &[String]) -> Option<String> {
    if path.is_empty() {
        return Some("lib.rs".into());
    }
    let base = path.join("/");
    let src = root().join("src");
    if src.join(format!("{base}.rs")).is_file() {
        Some(format!("{base}.rs"))
    } else if src.join(&base).join("mod.rs").is_file() {
        Some(format!("{base}/mod.rs"))
    } else {
        None
    }
}

/// `text` without comments, string and character literals, and `#[cfg(test)]` modules.
fn code_of(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            let mut depth = 0;
            while i < b.len() {
                if b[i..].starts_with(b"/*") {
                    depth += 1;
                    i += 2;
                } else if b[i..].starts_with(b"*/") {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if b[i] == b'r'
            && (b.get(i + 1) == Some(&b'"') || b.get(i + 1) == Some(&b'#'))
            && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_'))
        {
            // raw string r"..." or r#"..."#
            let mut j = i + 1;
            let mut hashes = 0;
            while b.get(j) == Some(&b'#') {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&b'"') {
                out.push('r');
                i += 1;
                continue;
            }
            let close: Vec<u8> = std::iter::once(b'"')
                .chain(std::iter::repeat_n(b'#', hashes))
                .collect();
            j += 1;
            while j < b.len() && !b[j..].starts_with(&close) {
                j += 1;
            }
            i = j + close.len();
            out.push_str("\"\"");
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else if b[i] == b'\'' {
            // a character literal ('x', '\n', '\u{..}') or a lifetime ('a)
            let rest = &text[i + 1..];
            let lit = if rest.starts_with('\\') {
                rest.find('\'').map(|e| e + 2)
            } else {
                let mut cs = rest.chars();
                match (cs.next(), cs.next()) {
                    (Some(c), Some('\'')) => Some(c.len_utf8() + 2),
                    _ => None,
                }
            };
            match lit {
                Some(len) => {
                    i += len;
                    out.push_str("' '");
                }
                None => {
                    out.push('\'');
                    i += 1;
                }
            }
        } else {
            let c = text[i..].chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    // #[cfg(test)] modules, to their closing brace
    while let Some(at) = out.find("#[cfg(test)]") {
        let after = &out[at..];
        let Some(open) = after.find(['{', ';']) else {
            break;
        };
        let end = if after.as_bytes()[open] == b';' {
            at + open + 1
        } else {
            let mut depth = 0;
            let mut end = out.len();
            for (k, c) in after.char_indices().skip(open) {
                match c {
                    '{' => depth += 1,
                    '}' => {
                        depth -= 1;
                        if depth == 0 {
                            end = at + k + 1;
                            break;
                        }
                    }
                    _ => {}
                }
            }
            end
        };
        out.replace_range(at..end, "");
    }
    out
}

/// The paths of a `use` tree (`a::{b, c::{d, e as f}}` -> a::b, a::c::d, a::c::e).
fn expand_use(tree: &str, prefix: &[String], out: &mut Vec<Vec<String>>) {
    // `e as f` keeps `e`: the alias marked before the blanks go
    let tree = tree
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .replace(" as ", "@");
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    let mut items = Vec::new();
    let (mut depth, mut cur) = (0, String::new());
    for c in tree.chars() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            _ => {}
        }
        if c == ',' && depth == 0 {
            items.push(std::mem::take(&mut cur));
        } else {
            cur.push(c);
        }
    }
    items.push(cur);
    for item in items.into_iter().filter(|s| !s.is_empty()) {
        if let Some(open) = item.find('{') {
            let mut p = prefix.to_vec();
            p.extend(
                item[..open]
                    .split("::")
                    .filter(|s| !s.is_empty())
                    .map(String::from),
            );
            expand_use(&item[open + 1..item.rfind('}').unwrap()], &p, out);
        } else {
            let item = item.split('@').next().unwrap_or(&item).to_string();
            let mut p = prefix.to_vec();
            p.extend(
                item.split("::")
                    .filter(|s| !s.is_empty() && *s != "*")
                    .map(String::from),
            );
            out.push(p);
        }
    }
}

/// Every module path `code` (of the module at `module`) refers to, relative to the crate root;
/// `reexports`, if given, collects what `pub use` makes visible under another name.
fn paths_of(
    code: &str,
    module: &[String],
    mut reexports: Option<&mut BTreeMap<String, Vec<String>>>,
) -> Vec<Vec<String>> {
    let mut raw: Vec<(Vec<String>, bool)> = Vec::new();
    let mut rest = code;
    while let Some(at) = find_word(rest, "use") {
        let public = rest[..at].trim_end().ends_with("pub") || rest[..at].trim_end().ends_with(')');
        let tail = &rest[at + 3..];
        let Some(end) = tail.find(';') else { break };
        let mut paths = Vec::new();
        expand_use(&tail[..end], &[], &mut paths);
        raw.extend(paths.into_iter().map(|p| (p, public)));
        rest = &tail[end..];
    }
    for keyword in ["crate::", "super::", "self::"] {
        let mut rest = code;
        while let Some(at) = rest.find(keyword) {
            let before = rest[..at].chars().last();
            let tail = &rest[at..];
            rest = &rest[at + keyword.len()..];
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            // `pub(in crate::m)` names who may see an item, not what it uses
            if code[..code.len() - tail.len()]
                .trim_end()
                .ends_with("pub(in")
            {
                continue;
            }
            let end = tail
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(tail.len());
            let p: Vec<String> = tail[..end]
                .split("::")
                .filter(|s| !s.is_empty())
                .map(String::from)
                .collect();
            // `super::{a, b}` is a use tree, read whole above
            if p.iter()
                .any(|s| !matches!(s.as_str(), "crate" | "super" | "self"))
            {
                raw.push((p, false));
            }
        }
    }
    let mut out = Vec::new();
    for (p, public) in raw {
        let Some(first) = p.first() else { continue };
        let absolute: Vec<String> = match first.as_str() {
            "crate" => p[1..].to_vec(),
            "super" | "self" => {
                let mut base = module.to_vec();
                let mut k = 0;
                while k < p.len() && (p[k] == "super" || p[k] == "self") {
                    if p[k] == "super" {
                        base.pop();
                    }
                    k += 1;
                }
                base.extend(p[k..].iter().cloned());
                base
            }
            name => {
                // a path relative to this module: one of its child modules
                let mut child = module.to_vec();
                child.push(name.to_string());
                if module_file(&child).is_none() {
                    continue;
                }
                child.extend(p[1..].iter().cloned());
                child
            }
        };
        if public {
            if let (Some(map), Some(last)) = (reexports.as_deref_mut(), absolute.last()) {
                map.insert(last.clone(), absolute.clone());
            }
        }
        out.push(absolute);
    }
    out
}

/// The byte offset of `word` in `text` as a whole word, if any.
fn find_word(text: &str, word: &str) -> Option<usize> {
    let mut from = 0;
    while let Some(at) = text[from..].find(word) {
        let at = from + at;
        let ok_before = at == 0
            || !text[..at]
                .chars()
                .last()
                .is_some_and(|c| c.is_alphanumeric() || c == '_');
        let ok_after = text[at + word.len()..].starts_with(|c: char| c.is_whitespace());
        if ok_before && ok_after {
            return Some(at);
        }
        from = at + word.len();
    }
    None
}

struct Crate {
    /// Per file, the module paths its code refers to.
    paths: BTreeMap<String, Vec<Vec<String>>>,
    /// Per module file, the names its `pub use` makes visible and where they come from.
    faces: BTreeMap<String, BTreeMap<String, Vec<String>>>,
}

impl Crate {
    fn read() -> Self {
        let mut files = Vec::new();
        source_files(&root().join("src"), &mut files);
        let mut paths = BTreeMap::new();
        let mut faces = BTreeMap::new();
        for f in files {
            let text = code_of(&std::fs::read_to_string(root().join("src").join(&f)).unwrap());
            let mut face = BTreeMap::new();
            let used = paths_of(&text, &module_of(&f), Some(&mut face));
            faces.insert(f.clone(), face);
            paths.insert(f, used);
        }
        Self { paths, faces }
    }

    /// The file that defines what `path` names: the deepest module file on it, followed
    /// through that module's `pub use` when the next name is re-exported there.
    fn resolve(&self, path: &[String], hops: usize) -> String {
        let mut k = 0;
        while k < path.len() && module_file(&path[..=k]).is_some() {
            k += 1;
        }
        let file = module_file(&path[..k]).unwrap();
        if hops < 8 && k < path.len() {
            if let Some(target) = self.faces.get(&file).and_then(|face| face.get(&path[k])) {
                if target.as_slice() != path {
                    let mut next = target.clone();
                    next.extend(path[k + 1..].iter().cloned());
                    return self.resolve(&next, hops + 1);
                }
            }
        }
        file
    }

    /// Per file, the files it uses.
    fn edges(&self) -> BTreeMap<String, BTreeSet<String>> {
        let mut out = BTreeMap::new();
        for (f, paths) in &self.paths {
            let targets: BTreeSet<String> = paths
                .iter()
                .map(|p| self.resolve(p, 0))
                .filter(|t| t != f && t != "lib.rs")
                .collect();
            out.insert(f.clone(), targets);
        }
        out
    }
}

/// The cycles of `edges`: its strongly connected components of more than one file.
fn cycles(edges: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    // Tarjan's algorithm, iterative
    let names: Vec<&String> = edges.keys().collect();
    let index_of: BTreeMap<&String, usize> =
        names.iter().enumerate().map(|(i, n)| (*n, i)).collect();
    let succ: Vec<Vec<usize>> = names
        .iter()
        .map(|n| {
            edges[*n]
                .iter()
                .filter_map(|t| index_of.get(t).copied())
                .collect()
        })
        .collect();
    let n = names.len();
    let (mut index, mut low, mut on) = (vec![usize::MAX; n], vec![0; n], vec![false; n]);
    let (mut stack, mut next, mut out) = (Vec::new(), 0, Vec::new());
    for start in 0..n {
        if index[start] != usize::MAX {
            continue;
        }
        let mut work = vec![(start, 0usize)];
        while let Some(&mut (v, ref mut k)) = work.last_mut() {
            if *k == 0 {
                index[v] = next;
                low[v] = next;
                next += 1;
                stack.push(v);
                on[v] = true;
            }
            if *k < succ[v].len() {
                let w = succ[v][*k];
                *k += 1;
                if index[w] == usize::MAX {
                    work.push((w, 0));
                } else if on[w] {
                    low[v] = low[v].min(index[w]);
                }
                continue;
            }
            work.pop();
            if let Some(&(parent, _)) = work.last() {
                low[parent] = low[parent].min(low[v]);
            }
            if low[v] == index[v] {
                let mut component = Vec::new();
                loop {
                    let w = stack.pop().unwrap();
                    on[w] = false;
                    component.push(names[w].clone());
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    out.push(component);
                }
            }
        }
    }
    out
}

fn top_module(file: &str) -> String {
    module_of(file).first().cloned().unwrap_or_default()
}

#[test]
fn no_file_uses_a_higher_layer() {
    let layers = layer_table();
    let layer_of: BTreeMap<String, usize> = layers
        .iter()
        .enumerate()
        .flat_map(|(i, (_, ms))| ms.iter().map(move |m| (m.clone(), i)))
        .collect();
    let krate = Crate::read();
    let mut missing = BTreeSet::new();
    let mut climbs = Vec::new();
    for (f, targets) in krate.edges() {
        if f == "lib.rs" {
            continue;
        }
        let Some(&from) = layer_of.get(&top_module(&f)) else {
            missing.insert(top_module(&f));
            continue;
        };
        for t in targets {
            if let Some(&to) = layer_of.get(&top_module(&t)) {
                if to > from {
                    climbs.push(format!(
                        "{f} ({}) uses {t} ({})",
                        layers[from].0, layers[to].0
                    ));
                }
            }
        }
    }
    assert!(
        missing.is_empty(),
        "modules missing from the layer table of docs/architecture.md: {missing:?}"
    );
    assert!(
        climbs.is_empty(),
        "{} imports climb a layer:\n{}",
        climbs.len(),
        climbs.join("\n")
    );
}

/// The cycles of files still to be untied, each given as what its files share (a folder ending
/// in `/`, files, or a module's file and folder by the module's name): a cycle may only lie
/// within one of these, and an entry no cycle lies in any more must go. The list only
/// shrinks; the goal is none.
const KNOWN_KNOTS: &[&str] = &["algorithms/batch/"];

/// Whether `file` belongs to the knot `known` ([`KNOWN_KNOTS`]).
fn in_knot(file: &str, known: &str) -> bool {
    known.split(' ').any(|k| {
        if k.ends_with('/') {
            file.starts_with(k)
        } else if k.ends_with(".rs") {
            file == k
        } else {
            file == format!("{k}.rs") || file.starts_with(&format!("{k}/"))
        }
    })
}

#[test]
fn no_files_use_each_other_in_a_cycle() {
    let found = cycles(&Crate::read().edges());
    let new: Vec<String> = found
        .iter()
        .filter(|c| !KNOWN_KNOTS.iter().any(|k| c.iter().all(|f| in_knot(f, k))))
        .map(|c| c.join(", "))
        .collect();
    assert!(
        new.is_empty(),
        "{} new cycles of files:\n{}",
        new.len(),
        new.join("\n")
    );
    let stale: Vec<&&str> = KNOWN_KNOTS
        .iter()
        .filter(|k| !found.iter().any(|c| c.iter().all(|f| in_knot(f, k))))
        .collect();
    assert!(
        stale.is_empty(),
        "no cycle lies in {stale:?} any more: take it off KNOWN_KNOTS"
    );
}

/// The checker itself, on code written for it: comments, strings, test modules and
/// relative paths.
#[test]
fn the_checker_reads_paths_as_the_compiler_does() {
    let code = code_of(
        "use crate::{a::b, c::{d, e as f}};\n// use crate::hidden;\nlet s = \"crate::in_string\";\n\
         let c = '\"'; fn g<'a>(x: &'a str) { crate::h::i(x) }\n#[cfg(test)]\nmod tests { use crate::tested; }\n\
         pub use super::sibling::Thing;\nuse child::X;\npub(in crate::seen_by) fn k() {}",
    );
    let paths = paths_of(&code, &["local".into(), "plan".into()], None);
    let shown: BTreeSet<String> = paths.iter().map(|p| p.join("::")).collect();
    for expected in ["a::b", "c::d", "c::e", "h::i", "local::sibling::Thing"] {
        assert!(
            shown.contains(expected),
            "{expected} not found in {shown:?}"
        );
    }
    for absent in ["hidden", "in_string", "tested", "seen_by"] {
        assert!(
            !shown.iter().any(|p| p.contains(absent)),
            "{absent} found in {shown:?}"
        );
    }
    let mut edges = BTreeMap::new();
    edges.insert("a".to_string(), BTreeSet::from(["b".to_string()]));
    edges.insert("b".to_string(), BTreeSet::from(["c".to_string()]));
    edges.insert(
        "c".to_string(),
        BTreeSet::from(["a".to_string(), "d".to_string()]),
    );
    edges.insert("d".to_string(), BTreeSet::new());
    assert_eq!(
        cycles(&edges),
        vec![vec!["a".to_string(), "b".into(), "c".into()]]
    );
}

/// What a file uses, as the checker resolves it, for a reader untying a cycle:
/// `ARCHITECTURE_FILE=urdf/write.rs cargo test --test architecture -- --ignored --nocapture`.
#[test]
#[ignore]
fn show_what_a_file_uses() {
    let file = std::env::var("ARCHITECTURE_FILE").unwrap_or_else(|_| "lib.rs".into());
    let edges = Crate::read().edges();
    println!("{file} uses {:#?}", edges.get(&file));
}
