//! The library's files import each other without cycles, and nothing
//! outside `viewer/` imports the viewer. Read from the source text: every
//! `crate::…` and `super::…` path (in `use` trees and in code), and a
//! `mod.rs`'s uses of its own children, counted as one file using another.
//! Tests (`#[cfg(test)]` to the end of a file) and comments do not count.

use crate::common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

type Graph = BTreeMap<String, BTreeSet<String>>;

/// `src/scene/mod.rs` → `scene`, `src/scene/nff.rs` → `scene::nff`.
fn module_name(relative: &Path) -> String {
    let mut parts: Vec<String> = relative
        .with_extension("")
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if parts.last().map(String::as_str) == Some("mod") {
        parts.pop();
    }
    parts.join("::")
}

/// The code of a file that builds into the library: no tests, no comments.
fn code_of(text: &str) -> String {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    text.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The paths a `use` tree names: `a::{b, c::{d, e}}` → `a::b`, `a::c::d`, `a::c::e`.
fn expand_use_tree(prefix: &str, tree: &str) -> Vec<String> {
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    let Some(open) = tree.find('{') else {
        return vec![join(prefix, &tree)];
    };
    let head = join(prefix, tree[..open].trim_end_matches("::"));
    let inner = &tree[open + 1..tree.len().saturating_sub(1)];
    let (mut out, mut depth, mut start) = (Vec::new(), 0, 0);
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                out.extend(expand_use_tree(&head, &inner[start..i]));
                start = i + 1;
            }
            _ => {}
        }
    }
    if start < inner.len() {
        out.extend(expand_use_tree(&head, &inner[start..]));
    }
    out
}

fn join(prefix: &str, rest: &str) -> String {
    match (prefix.is_empty(), rest.is_empty()) {
        (true, _) => rest.to_string(),
        (_, true) => prefix.to_string(),
        _ => format!("{prefix}::{rest}"),
    }
}

/// Every `crate::…`/`super::…` path in the code, `use` trees expanded.
fn paths_in(code: &str) -> Vec<String> {
    let mut paths = Vec::new();
    for statement in code.split(';') {
        let s = statement.trim_start();
        let s = s.strip_prefix("pub ").unwrap_or(s).trim_start();
        let s = s.strip_prefix("pub(crate) ").unwrap_or(s).trim_start();
        if let Some(tree) = s.strip_prefix("use ")
            && (tree.starts_with("crate::") || tree.starts_with("super::"))
        {
            paths.extend(expand_use_tree("", tree));
        }
    }
    let ident = |c: char| c.is_alphanumeric() || c == '_' || c == ':';
    for root in ["crate::", "super::"] {
        for (at, _) in code.match_indices(root) {
            let before = code[..at].chars().next_back();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let end = code[at..]
                .find(|c| !ident(c))
                .map_or(code.len(), |e| at + e);
            paths.push(code[at..end].trim_end_matches(':').to_string());
        }
    }
    paths
}

/// The module a path lands in: its longest prefix that is a file, or the
/// parent module itself when the path names an item defined there.
fn resolve(modules: &BTreeSet<String>, base: &[&str], path: &str) -> Option<String> {
    let parts: Vec<&str> = path.split("::").filter(|p| !p.is_empty()).collect();
    for k in (1..=parts.len()).rev() {
        let candidate = base
            .iter()
            .chain(&parts[..k])
            .copied()
            .collect::<Vec<_>>()
            .join("::");
        if modules.contains(&candidate) {
            return Some(candidate);
        }
    }
    let parent = base.join("::");
    modules.contains(&parent).then_some(parent)
}

/// Which file of the library uses which, for the tree under `src`.
fn module_graph(src: &Path) -> Graph {
    let mut files = Vec::new();
    let mut pending = vec![src.to_path_buf()];
    while let Some(dir) = pending.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                if path.file_name().is_some_and(|n| n != "bin") {
                    pending.push(path);
                }
            } else if path.extension().is_some_and(|e| e == "rs")
                && path != src.join("lib.rs")
                // A module's unit tests in their own file are tests too.
                && path.file_name().is_some_and(|n| n != "tests.rs")
            {
                files.push(path);
            }
        }
    }
    let modules: BTreeSet<String> = files
        .iter()
        .map(|f| module_name(f.strip_prefix(src).unwrap()))
        .collect();
    let mut graph = Graph::new();
    for file in &files {
        let name = module_name(file.strip_prefix(src).unwrap());
        let code = code_of(&std::fs::read_to_string(file).unwrap());
        let is_mod_rs = file.file_name().is_some_and(|n| n == "mod.rs");
        let own: Vec<&str> = name.split("::").collect();
        // `super` of `scene::nff` is `scene`; of `scene` (its mod.rs), the crate.
        let parent = &own[..own.len() - 1];
        let mut uses = BTreeSet::new();
        for path in paths_in(&code) {
            let target = if let Some(rest) = path.strip_prefix("crate::") {
                resolve(&modules, &[], rest)
            } else if let Some(rest) = path.strip_prefix("super::") {
                resolve(&modules, parent, rest)
            } else {
                None
            };
            uses.extend(target);
        }
        if is_mod_rs {
            // A mod.rs uses a child it declares when it names it in code.
            for line in code.lines() {
                let l = line.trim();
                let l = l.strip_prefix("pub ").unwrap_or(l);
                if let Some(child) = l.strip_prefix("mod ").and_then(|c| c.strip_suffix(';'))
                    && code.contains(&format!("{child}::"))
                {
                    uses.insert(format!("{name}::{child}"));
                }
            }
        }
        uses.remove(&name);
        graph.insert(name, uses);
    }
    graph
}

/// A cycle of the graph, if it has one (depth-first search).
fn find_cycle(graph: &Graph) -> Option<Vec<String>> {
    fn visit<'a>(
        graph: &'a Graph,
        node: &'a str,
        path: &mut Vec<&'a str>,
        done: &mut BTreeSet<&'a str>,
    ) -> Option<Vec<String>> {
        if let Some(at) = path.iter().position(|n| *n == node) {
            let mut cycle: Vec<String> = path[at..].iter().map(|s| s.to_string()).collect();
            cycle.push(node.to_string());
            return Some(cycle);
        }
        if done.contains(node) {
            return None;
        }
        path.push(node);
        for next in graph.get(node).into_iter().flatten() {
            if let Some(cycle) = visit(graph, next, path, done) {
                return Some(cycle);
            }
        }
        path.pop();
        done.insert(node);
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|node| visit(graph, node, &mut Vec::new(), &mut done))
}

#[test]
fn the_library_files_import_each_other_without_cycles() {
    let graph = module_graph(&common::repo_path("src"));
    assert!(graph.len() > 30, "{} files read", graph.len());
    assert!(
        graph["render::renderer"].contains("accel"),
        "the parser sees uses"
    );
    if let Some(cycle) = find_cycle(&graph) {
        panic!("import cycle: {}", cycle.join(" → "));
    }
}

/// Each file's layer: 0 for a file that uses no other, else one above the
/// highest file it uses (the graph has no cycles).
fn layers(graph: &Graph) -> BTreeMap<String, usize> {
    fn layer_of(graph: &Graph, node: &str, memo: &mut BTreeMap<String, usize>) -> usize {
        if let Some(&l) = memo.get(node) {
            return l;
        }
        let l = graph
            .get(node)
            .into_iter()
            .flatten()
            .map(|u| layer_of(graph, u, memo) + 1)
            .max()
            .unwrap_or(0);
        memo.insert(node.to_string(), l);
        l
    }
    let mut memo = BTreeMap::new();
    for node in graph.keys() {
        layer_of(graph, node, &mut memo);
    }
    memo
}

/// The drawing of the library, bottom layer first:
/// `cargo test --release --test integration module_graph -- --nocapture`.
#[test]
fn the_layers_of_the_library() {
    let graph = module_graph(&common::repo_path("src"));
    if let Some(cycle) = find_cycle(&graph) {
        panic!("no layers: import cycle {}", cycle.join(" → "));
    }
    let layers = layers(&graph);
    let top = layers.values().copied().max().unwrap_or(0);
    for k in 0..=top {
        let files: Vec<&str> = layers
            .iter()
            .filter(|(_, l)| **l == k)
            .map(|(f, _)| f.as_str())
            .collect();
        eprintln!("layer {k}: {}", files.join(", "));
    }
    // Every file that uses another sits above it.
    for (file, uses) in &graph {
        for used in uses {
            assert!(layers[file] > layers[used], "{file} uses {used}");
        }
    }
    // The core math is at the bottom and the viewer's app at the top.
    assert_eq!(layers["math"], 0);
    assert!(layers["viewer::app"] > layers["render::renderer"]);

    // The same drawing by top-level module, where those form no cycle.
    let mut modules = Graph::new();
    for (file, uses) in &graph {
        let top = |f: &str| f.split("::").next().unwrap_or(f).to_string();
        let entry = modules.entry(top(file)).or_default();
        entry.extend(uses.iter().map(|u| top(u)).filter(|u| *u != top(file)));
    }
    match find_cycle(&modules) {
        Some(cycle) => eprintln!("top-level modules use each other: {}", cycle.join(" → ")),
        None => {
            let layers = self::layers(&modules);
            for k in 0..=layers.values().copied().max().unwrap_or(0) {
                let names: Vec<&str> = layers
                    .iter()
                    .filter(|(_, l)| **l == k)
                    .map(|(m, _)| m.as_str())
                    .collect();
                eprintln!("module layer {k}: {}", names.join(", "));
            }
        }
    }
}

/// The library drawn by layer: its top-level modules (where those form no
/// cycle), then every file, bottom layer first.
fn drawing(graph: &Graph) -> String {
    let imports: usize = graph.values().map(BTreeSet::len).sum();
    let mut text = format!("{} files, {imports} imports between them.\n\n", graph.len());
    let mut modules = Graph::new();
    for (file, uses) in graph {
        let top = |f: &str| f.split("::").next().unwrap_or(f).to_string();
        let entry = modules.entry(top(file)).or_default();
        entry.extend(uses.iter().map(|u| top(u)).filter(|u| *u != top(file)));
    }
    let by_layer = |layers: &BTreeMap<String, usize>| {
        let top = layers.values().copied().max().unwrap_or(0);
        (0..=top)
            .map(|k| {
                let names: Vec<String> = layers
                    .iter()
                    .filter(|(_, l)| **l == k)
                    .map(|(name, _)| format!("`{name}`"))
                    .collect();
                format!("| {k} | {} |\n", names.join(", "))
            })
            .collect::<String>()
    };
    if find_cycle(&modules).is_none() {
        text += "| layer | top-level modules |\n|---:|---|\n";
        text += &by_layer(&layers(&modules));
        text += "\n";
    }
    text += "| layer | files |\n|---:|---|\n";
    text += &by_layer(&layers(graph));
    text
}

/// docs/design.md draws the layers the code has: after a change to the
/// imports, `GLINT_WRITE_DESIGN=1 cargo test --release --test integration
/// module_graph` writes the drawing again.
#[test]
fn the_design_document_draws_the_layers_the_code_has() {
    let graph = module_graph(&common::repo_path("src"));
    assert!(find_cycle(&graph).is_none());
    let drawn = drawing(&graph);
    let path = common::repo_path("docs/design.md");
    let text = std::fs::read_to_string(&path).unwrap();
    let (open, close) = ("<!-- module-layers -->\n", "<!-- /module-layers -->");
    let start = text
        .find(open)
        .expect("docs/design.md has a module-layers block")
        + open.len();
    let end = start + text[start..].find(close).expect("the block is closed");
    if std::env::var_os("GLINT_WRITE_DESIGN").is_some() {
        let written = format!("{}{drawn}{}", &text[..start], &text[end..]);
        std::fs::write(&path, written).unwrap();
        return;
    }
    assert!(
        text[start..end] == drawn,
        "docs/design.md's module layers differ from the code's; write them with \
         GLINT_WRITE_DESIGN=1 cargo test --release --test integration module_graph:\n{drawn}"
    );
}

#[test]
fn only_the_viewer_imports_the_viewer() {
    let graph = module_graph(&common::repo_path("src"));
    for (file, uses) in &graph {
        if !file.starts_with("viewer") {
            let into_viewer: Vec<_> = uses.iter().filter(|u| u.starts_with("viewer")).collect();
            assert!(into_viewer.is_empty(), "{file} uses {into_viewer:?}");
        }
    }
}

#[test]
fn the_checker_finds_cycles_through_parents_children_and_use_trees() {
    let dir = tempfile::tempdir().unwrap();
    let write = |path: &str, text: &str| {
        let path = dir.path().join(path);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    };
    write("lib.rs", "pub mod shapes;\npub mod math;\n");
    write("math.rs", "pub struct Ray;\n");
    write(
        "shapes/mod.rs",
        "mod sphere;\npub use sphere::Sphere;\npub struct Hit;\n",
    );
    // The child reaches an item of its parent through a use tree.
    write(
        "shapes/sphere.rs",
        "use crate::{math::Ray, shapes::{Hit}};\npub struct Sphere;\n#[cfg(test)]\nuse crate::nothing;\n",
    );
    let graph = module_graph(dir.path());
    assert_eq!(
        graph["shapes::sphere"],
        ["math", "shapes"].map(String::from).into()
    );
    assert_eq!(
        find_cycle(&graph).map(|c| c.len()),
        Some(3),
        "shapes → shapes::sphere → shapes"
    );
    write(
        "shapes/sphere.rs",
        "// use super::Hit;\npub struct Sphere;\n",
    );
    assert_eq!(find_cycle(&module_graph(dir.path())), None);
}
