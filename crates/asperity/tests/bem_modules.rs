//! The modules of `src/bem/` import one another without a cycle (DESIGN.md, "the BEM core as
//! one core with seams"): a module that names another (`use super::x::…`, a path
//! `super::x::…` or `crate::bem::x::…` in its code) depends on it, and following those
//! dependencies never leads back.
//!
//! A node is a file (a module's `mod.rs` stands for the module; `stiffness::cg` is a node of
//! its own). `bem/mod.rs` is the vocabulary every module may name (`HalfSpace`, `Control`,
//! `SolveError`, …): a name it only re-exports (`pub use solver::ContactSolver`) counts as
//! the module that defines it. A module that re-exports a name of its child (`pub(super) use
//! bccg::BccgScratch` in `iterations/mod.rs`) depends on that child. Test modules (`#[cfg(test)] mod …`, in a file or as files)
//! and comments are left out.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A module path below `bem` (`["stiffness", "cg"]`); empty for `bem` itself.
type Module = Vec<String>;

/// The module of a file below `bem/`.
fn module_of(relative: &Path) -> Module {
    let mut parts: Module = relative
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().expect("a file name");
    if last != "mod.rs" {
        parts.push(last.trim_end_matches(".rs").to_string());
    }
    parts
}

/// The `.rs` files below `dir`, recursively, sorted.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("bem/ is readable")
        .map(|e| e.expect("an entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of a file without comments and without its `#[cfg(test)] mod … { … }` blocks
/// (rustfmt layout: such a block ends at a `}` alone at the indentation of its `mod` line);
/// also the names of its `#[cfg(test)] mod name;` declarations (test-only files).
fn code_of(text: &str) -> (String, Vec<String>) {
    let lines: Vec<&str> = text.lines().collect();
    let (mut code, mut test_files) = (String::new(), Vec::new());
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        let next = lines.get(i + 1).map(|l| l.trim()).unwrap_or("");
        // `pub(in crate::bem) mod tests { … }`: a test module with fixtures for others.
        let next = match next.strip_prefix("pub") {
            Some(rest) if rest.starts_with('(') => rest.split_once(") ").map_or(next, |r| r.1),
            _ => next,
        };
        if line.trim() == "#[cfg(test)]" && next.starts_with("mod ") {
            let name = next[4..].trim_end_matches([';', '{', ' ']).to_string();
            if next.ends_with(';') {
                test_files.push(name);
                i += 2;
                continue;
            }
            let indent = &lines[i + 1][..lines[i + 1].len() - lines[i + 1].trim_start().len()];
            let end = format!("{indent}}}");
            i += 2;
            while i < lines.len() && lines[i] != end {
                i += 1;
            }
            i += 1;
            continue;
        }
        let without_comment = match line.find("//") {
            Some(at) => &line[..at],
            None => line,
        };
        code.push_str(without_comment);
        code.push('\n');
        i += 1;
    }
    (code, test_files)
}

/// The names `bem/mod.rs` re-exports, each with the module that defines it.
fn re_exports(code: &str) -> BTreeMap<String, String> {
    let mut names = BTreeMap::new();
    for statement in code.split(';') {
        let statement = statement.trim();
        let Some(rest) = statement.strip_prefix("pub use ") else {
            continue;
        };
        let Some((module, items)) = rest.split_once("::") else {
            continue;
        };
        let items = items.trim_start_matches('{').trim_end_matches('}');
        for item in items.split(',') {
            let item = item.trim();
            if !item.is_empty() {
                names.insert(item.to_string(), module.to_string());
            }
        }
    }
    names
}

/// Every path of `code` that starts at `bem` or above the file's own module (`super::…`,
/// `crate::bem::…`), brace groups of `use` statements expanded one level, as the module it
/// starts from and the segments after it.
fn paths(code: &str, module: &Module) -> Vec<(Module, Vec<String>)> {
    let mut found = Vec::new();
    let bytes = code.as_bytes();
    let mut at = 0;
    while at < code.len() {
        let rest = &code[at..];
        let (mut base, mut start) = if rest.starts_with("crate::bem::") {
            (Vec::new(), at + "crate::bem::".len())
        } else if rest.starts_with("super::")
            && (at == 0 || !(bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b':'))
        {
            (module.clone(), at)
        } else {
            at += rest.chars().next().map_or(1, char::len_utf8);
            continue;
        };
        let mut outside = false;
        while code[start..].starts_with("super::") {
            outside |= base.pop().is_none();
            start += "super::".len();
        }
        // The rest of the path: segments, or one brace group of them.
        let tail: String = code[start..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || "_:{}, \n".contains(*c))
            .collect();
        let (prefix, group) = match tail.find('{') {
            Some(open) => (
                &tail[..open],
                tail[open + 1..].split('}').next().unwrap_or(""),
            ),
            None => (tail.as_str(), ""),
        };
        let prefix: Vec<String> = prefix
            .split("::")
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .collect();
        if outside {
            // Above `bem`: another part of the crate.
        } else if group.is_empty() {
            found.push((base.clone(), prefix));
        } else {
            for item in group.split(',') {
                let mut segments = prefix.clone();
                segments.extend(
                    item.split("::")
                        .map(|s| s.trim().to_string())
                        .filter(|s| !s.is_empty()),
                );
                found.push((base.clone(), segments));
            }
        }
        at = start + tail.len().max(1);
    }
    found
}

/// The paths of the `use` statements of `code` that start at a child module of the file's
/// own (`pub(super) use bccg::BccgScratch` in `iterations/mod.rs`): a module that
/// re-exports a name of its child depends on the child, so that a path to the re-exported
/// name leads on to where it is defined.
fn child_paths(
    code: &str,
    module: &Module,
    modules: &BTreeSet<Module>,
) -> Vec<(Module, Vec<String>)> {
    let mut found = Vec::new();
    for statement in code.split(';') {
        let mut rest = statement.trim();
        if let Some(after) = rest.strip_prefix("pub") {
            rest = after.trim_start();
            if rest.starts_with('(') {
                rest = rest.split_once(')').map_or("", |(_, r)| r.trim_start());
            }
        }
        let Some(path) = rest.strip_prefix("use ") else {
            continue;
        };
        let Some((first, tail)) = path.split_once("::") else {
            continue;
        };
        let mut child = module.clone();
        child.push(first.trim().to_string());
        if !modules.contains(&child) {
            continue;
        }
        let tail = tail.trim().trim_start_matches('{').trim_end_matches('}');
        for item in tail.split(',') {
            let mut segments = vec![first.trim().to_string()];
            segments.extend(
                item.split("::")
                    .map(|s| s.trim().to_string())
                    .filter(|s| !s.is_empty()),
            );
            found.push((module.clone(), segments));
        }
    }
    found
}

/// The module a path leads to: the longest run of its segments that names a module (a name
/// that `bem/mod.rs` re-exports counts as its defining module).
fn target(
    (base, segments): (&Module, &[String]),
    modules: &BTreeSet<Module>,
    exported: &BTreeMap<String, String>,
) -> Module {
    let mut module = base.clone();
    for segment in segments {
        let mut deeper = module.clone();
        deeper.push(segment.clone());
        if modules.contains(&deeper) {
            module = deeper;
        } else {
            if module.is_empty() {
                if let Some(defining) = exported.get(segment) {
                    module = vec![defining.clone()];
                }
            }
            break;
        }
    }
    module
}

/// The dependencies of every module of `bem/` on the others (vocabulary and self left out).
fn dependencies() -> BTreeMap<Module, BTreeSet<Module>> {
    let bem = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/bem");
    let mut files = Vec::new();
    rust_files(&bem, &mut files);
    let mut sources = BTreeMap::new();
    let mut test_only: BTreeSet<Module> = BTreeSet::new();
    for file in &files {
        let module = module_of(file.strip_prefix(&bem).expect("below bem/"));
        let (code, tests) = code_of(&std::fs::read_to_string(file).expect("a readable file"));
        for name in tests {
            let mut child = module.clone();
            child.push(name);
            test_only.insert(child);
        }
        sources.insert(module, code);
    }
    // Files inside a test-only module are test code too.
    sources.retain(|m, _| !test_only.iter().any(|t| m.starts_with(t)));
    let modules: BTreeSet<Module> = sources.keys().cloned().collect();
    let exported = re_exports(&sources[&Vec::new()]);
    let mut graph = BTreeMap::new();
    for (module, code) in &sources {
        let mut found = paths(code, module);
        found.extend(child_paths(code, module, &modules));
        let edges: BTreeSet<Module> = found
            .iter()
            .map(|(base, segments)| target((base, segments), &modules, &exported))
            .filter(|t| !t.is_empty() && t != module && !module.starts_with(t))
            .collect();
        graph.insert(module.clone(), edges);
    }
    graph
}

/// A cycle through the graph, if any (depth-first search), as the modules along it.
fn find_cycle(graph: &BTreeMap<Module, BTreeSet<Module>>) -> Option<Vec<Module>> {
    fn visit(
        node: &Module,
        graph: &BTreeMap<Module, BTreeSet<Module>>,
        state: &mut BTreeMap<Module, u8>,
        stack: &mut Vec<Module>,
    ) -> Option<Vec<Module>> {
        state.insert(node.clone(), 1);
        stack.push(node.clone());
        for next in graph.get(node).into_iter().flatten() {
            match state.get(next).copied().unwrap_or(0) {
                1 => {
                    let from = stack.iter().position(|m| m == next).expect("on the stack");
                    let mut cycle = stack[from..].to_vec();
                    cycle.push(next.clone());
                    return Some(cycle);
                }
                0 => {
                    if let Some(cycle) = visit(next, graph, state, stack) {
                        return Some(cycle);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(node.clone(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for node in graph.keys() {
        if state.get(node).copied().unwrap_or(0) == 0 {
            if let Some(cycle) = visit(node, graph, &mut state, &mut Vec::new()) {
                return Some(cycle);
            }
        }
    }
    None
}

fn name(module: &Module) -> String {
    module.join("::")
}

#[test]
fn the_bem_modules_import_one_another_without_a_cycle() {
    let graph = dependencies();
    // The reader sees what the test sees: a few edges it must find.
    let edge = |from: &str, to: &str| {
        graph
            .iter()
            .find(|(m, _)| name(m) == from)
            .is_some_and(|(_, e)| e.iter().any(|t| name(t) == to))
    };
    assert!(edge("iterations::bccg", "interface"), "{graph:?}");
    assert!(edge("stiffness::cg", "precondition"), "{graph:?}");
    assert!(
        edge("precondition", "precondition::ring_extension"),
        "{graph:?}"
    );
    assert!(
        edge("iterations", "iterations::bccg::small_set"),
        "{graph:?}"
    );
    if let Some(cycle) = find_cycle(&graph) {
        let path: Vec<String> = cycle.iter().map(name).collect();
        panic!("an import cycle in bem/: {}", path.join(" -> "));
    }
}

#[test]
fn the_check_finds_a_cycle() {
    // The search on a graph with a cycle a -> b -> c -> a (and a tail d -> a).
    let module = |s: &str| vec![s.to_string()];
    let mut graph = BTreeMap::new();
    for (from, to) in [("a", "b"), ("b", "c"), ("c", "a"), ("d", "a")] {
        graph
            .entry(module(from))
            .or_insert_with(BTreeSet::new)
            .insert(module(to));
    }
    let cycle = find_cycle(&graph).expect("a cycle");
    assert_eq!(cycle.first(), cycle.last());
    assert_eq!(cycle.len(), 4);
    graph.get_mut(&module("c")).unwrap().clear();
    assert_eq!(find_cycle(&graph), None);
    // And the parsing: a brace group, nested supers, a re-exported name.
    let code =
        "use super::{bccg::Sums, interface::Interface, ContactSolver};\nuse super::super::x::Y;\n";
    let found = paths(code, &module("stiffness"));
    assert_eq!(found.len(), 3, "{found:?}");
    let modules: BTreeSet<Module> = ["bccg", "interface", "solver", "x", "stiffness"]
        .iter()
        .map(|s| module(s))
        .collect();
    let exported = BTreeMap::from([("ContactSolver".to_string(), "solver".to_string())]);
    let targets: Vec<String> = found
        .iter()
        .map(|(b, s)| name(&target((b, s), &modules, &exported)))
        .collect();
    // (`super::super::x` from `stiffness` is outside `bem`: not a path of it.)
    assert_eq!(targets, ["bccg", "interface", "solver"]);
}
