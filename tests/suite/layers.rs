//! The crate's layers against its imports: `src/lib.rs` lists the layers from the bottom up (one
//! `- [`module`]` line each), the book's contributing page lists the same in its code-layout
//! table, no module of `src/` names (`crate::…`, outside comments) a module above its own, and
//! no files import each other in a circle, of two files or more (through `crate::` or
//! `super::`; a module's root and its own files aside). A new top-level module must be placed
//! in both lists.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

/// The layers as `src/lib.rs`'s opening comment lists them, from the bottom up.
fn layers_of_lib(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| l.strip_prefix("//! - [`"))
        .filter_map(|l| l.split_once('`').map(|(name, _)| name.to_owned()))
        .collect()
}

/// The layers as the contributing page's code-layout table lists them (the first name of each
/// row, `physics/` or `run.rs` read as the module), from the bottom up.
fn layers_of_book(text: &str) -> Vec<String> {
    let table = text
        .split("## Code layout")
        .nth(1)
        .expect("a code-layout section")
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'));
    table
        .filter_map(|row| row.strip_prefix("| `"))
        .filter_map(|row| row.split_once('`').map(|(name, _)| name))
        .map(|name| {
            name.trim_end_matches('/')
                .trim_end_matches(".rs")
                .to_owned()
        })
        .collect()
}

/// The top-level modules `src/lib.rs` declares.
fn declared_modules(text: &str) -> BTreeSet<String> {
    text.lines()
        .filter_map(|l| l.trim().strip_prefix("pub mod "))
        .map(|l| l.trim_end_matches(';').to_owned())
        .collect()
}

/// The names `src/lib.rs` re-exports at the crate's root (`pub use error::{Error, Result};`),
/// each with the module it comes from: `crate::Error` names `error`.
fn root_reexports(text: &str) -> BTreeMap<String, String> {
    let mut names = BTreeMap::new();
    for line in text.lines() {
        let Some(path) = line.trim().strip_prefix("pub use ") else {
            continue;
        };
        let (module, items) = path.trim_end_matches(';').split_once("::").unwrap();
        for item in items.trim_matches(|c| c == '{' || c == '}').split(',') {
            let name = item.rsplit("::").next().unwrap().trim();
            names.insert(name.to_owned(), module.to_owned());
        }
    }
    names
}

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level modules a file's code names through `crate::` (comments left out; a group
/// `crate::{a, b::c}` names each of its items).
fn modules_named(text: &str) -> BTreeSet<String> {
    let ident = |s: &str| {
        s.trim_start()
            .split(|c: char| !(c.is_alphanumeric() || c == '_'))
            .next()
            .unwrap_or("")
            .to_owned()
    };
    let mut named = BTreeSet::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        for (at, _) in code.match_indices("crate::") {
            if at > 0 && code[..at].ends_with('$') {
                continue;
            }
            let rest = &code[at + "crate::".len()..];
            match rest.strip_prefix('{') {
                Some(group) => {
                    let mut depth = 0;
                    let mut item = String::new();
                    for c in group.chars() {
                        match c {
                            '{' => depth += 1,
                            '}' if depth == 0 => break,
                            '}' => depth -= 1,
                            ',' if depth == 0 => {
                                named.insert(ident(&item));
                                item.clear();
                                continue;
                            }
                            _ => {}
                        }
                        item.push(c);
                    }
                    named.insert(ident(&item));
                }
                None => {
                    named.insert(ident(rest));
                }
            }
        }
    }
    named.remove("");
    named
}

/// The top-level module a file of `src/` belongs to (`None` for the crate root and the binary).
fn module_of(src: &Path, file: &Path) -> Option<String> {
    let relative = file.strip_prefix(src).unwrap();
    let first = relative.components().next()?.as_os_str().to_str()?;
    let name = first.trim_end_matches(".rs");
    (name != "lib" && name != "main").then(|| name.to_owned())
}

#[test]
fn the_layers_are_listed_alike_in_the_crate_and_the_book() {
    let lib = read(&root().join("src/lib.rs"));
    let layers = layers_of_lib(&lib);
    assert_eq!(
        layers.iter().cloned().collect::<BTreeSet<_>>(),
        declared_modules(&lib),
        "src/lib.rs lists each module it declares once as a layer"
    );
    let book = layers_of_book(&read(&root().join("docs/book/src/contributing.md")));
    assert_eq!(
        book, layers,
        "the contributing page's code layout lists the layers of src/lib.rs, in its order"
    );
}

#[test]
fn no_module_imports_one_above_it() {
    let lib = read(&root().join("src/lib.rs"));
    let (layers, reexports) = (layers_of_lib(&lib), root_reexports(&lib));
    let rank = |m: &str| {
        let m = reexports.get(m).map_or(m, String::as_str);
        layers.iter().position(|l| l == m)
    };
    let src = root().join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut upward = Vec::new();
    for file in &files {
        let Some(module) = module_of(&src, file) else {
            continue;
        };
        let own = rank(&module).unwrap_or_else(|| panic!("{module} is in no layer"));
        for named in modules_named(&read(file)) {
            let theirs = rank(&named).unwrap_or_else(|| {
                panic!(
                    "{} names crate::{named}, which is in no layer",
                    file.display()
                )
            });
            if theirs > own {
                upward.push(format!(
                    "{} ({module}) imports {named}",
                    file.strip_prefix(root()).unwrap().display()
                ));
            }
        }
    }
    assert!(
        upward.is_empty(),
        "imports of a layer above:\n{}",
        upward.join("\n")
    );
}

/// The reader of imports sees what it should: grouped, nested and single paths, not comments.
#[test]
fn imports_are_read_from_code_not_comments() {
    let text = "use crate::physics::disks::Disks;\n\
                use crate::{error::Result, scenario::{Floor, Scenario}};\n\
                /// See [`crate::studies`].\n\
                let x = crate::engine::Scene::build(s); // crate::run\n\
                macro_rules! m { () => { $crate::cli } }\n";
    let named: Vec<_> = modules_named(text).into_iter().collect();
    assert_eq!(named, ["engine", "error", "physics", "scenario"]);
    let reexports =
        root_reexports("pub use error::{Error, Result};\npub use scenario::Scenario;\n");
    assert_eq!(reexports["Result"], "error");
    assert_eq!(reexports["Scenario"], "scenario");
}

/// A file's module path under `src/` (`run/streams.rs` is `run::streams`, `run.rs` and
/// `run/mod.rs` are `run`), `None` for the crate root and the binary.
fn module_path(src: &Path, file: &Path) -> Option<Vec<String>> {
    let relative = file.strip_prefix(src).unwrap().with_extension("");
    let mut path: Vec<String> = relative
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if path.last().is_some_and(|l| l == "mod") {
        path.pop();
    }
    (!path.is_empty() && path != ["lib"] && path != ["main"]).then_some(path)
}

/// The paths a file's code names through `crate::` or `super::` (comments and its tests left
/// out), each made absolute from the file's own module `own`.
fn paths_named(text: &str, own: &[String]) -> Vec<Vec<String>> {
    let code = text.split("#[cfg(test)]\nmod tests").next().unwrap_or("");
    let mut paths = Vec::new();
    for line in code.lines() {
        let line = line.split("//").next().unwrap_or("");
        for (at, _) in line
            .match_indices("crate::")
            .chain(line.match_indices("super::"))
        {
            let before = &line[..at];
            if before.ends_with('$') || before.ends_with("::") {
                continue;
            }
            let tail = &line[at..];
            let (mut base, mut rest) = match tail.strip_prefix("crate::") {
                Some(rest) => (Vec::new(), rest),
                None => (own[..own.len() - 1].to_vec(), &tail["super::".len()..]),
            };
            while let Some(r) = rest.strip_prefix("super::") {
                base.pop();
                rest = r;
            }
            expand(rest, base, &mut paths);
        }
    }
    paths
}

/// The paths of `rest` (after a `::`) below `base`, a group `{a, b::c}` giving one path each.
fn expand(rest: &str, mut base: Vec<String>, out: &mut Vec<Vec<String>>) {
    let mut rest = rest;
    loop {
        if let Some(group) = rest.strip_prefix('{') {
            let (mut depth, mut start) = (0, 0);
            for (k, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        expand(group[start..k].trim(), base.clone(), out);
                        return;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        expand(group[start..k].trim(), base.clone(), out);
                        start = k + 1;
                    }
                    _ => {}
                }
            }
            return;
        }
        let end = rest
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        if end == 0 {
            break;
        }
        base.push(rest[..end].to_owned());
        match rest[end..].strip_prefix("::") {
            Some(r) => rest = r,
            None => break,
        }
    }
    out.push(base);
}

#[test]
fn no_files_import_each_other_in_a_circle() {
    let src = root().join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let modules: BTreeMap<Vec<String>, PathBuf> = files
        .iter()
        .filter_map(|f| module_path(&src, f).map(|m| (m, f.clone())))
        .collect();
    // Each file's imports, as the files they reach (the longest module path that is a file),
    // leaving out its own module and its ancestors: a module's root and its files are one
    // module's parts, and the root names them to declare them.
    let mut imports: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (module, file) in &modules {
        for path in paths_named(&read(file), module) {
            let reached = (1..=path.len())
                .rev()
                .find_map(|n| modules.get_key_value(&path[..n]).map(|(k, _)| k));
            if let Some(other) =
                reached.filter(|o| !module.starts_with(o) && !o.starts_with(module))
            {
                imports
                    .entry(module.clone())
                    .or_default()
                    .insert(other.clone());
            }
        }
    }
    let circles: Vec<String> = circles(&imports)
        .iter()
        .map(|c| {
            let names: Vec<String> = c.iter().map(|m| m.join("::")).collect();
            names.join(" -> ")
        })
        .collect();
    assert!(
        circles.is_empty(),
        "files that import each other in a circle:\n{}",
        circles.join("\n")
    );
}

/// The circles of a graph (`edges`: each node's successors), each once, as a path from its
/// least node back to it: the shortest way round from each node, found breadth first.
fn circles<N: Ord + Clone>(edges: &BTreeMap<N, BTreeSet<N>>) -> Vec<Vec<N>> {
    let mut found: BTreeSet<Vec<N>> = BTreeSet::new();
    for start in edges.keys() {
        let mut came_from: BTreeMap<&N, &N> = BTreeMap::new();
        let mut frontier = vec![start];
        let mut back = None;
        while back.is_none() && !frontier.is_empty() {
            let mut next = Vec::new();
            for node in frontier {
                for to in edges.get(node).into_iter().flatten() {
                    if to == start {
                        back = Some(node);
                        break;
                    }
                    if !came_from.contains_key(to) {
                        came_from.insert(to, node);
                        next.push(to);
                    }
                }
                if back.is_some() {
                    break;
                }
            }
            frontier = next;
        }
        let Some(mut node) = back else { continue };
        let mut circle = vec![node.clone()];
        while node != start {
            node = came_from[node];
            circle.push(node.clone());
        }
        circle.reverse();
        // Started from its least node, so that each circle is found once.
        let least = (0..circle.len()).min_by_key(|&k| &circle[k]).unwrap();
        circle.rotate_left(least);
        circle.push(circle[0].clone());
        found.insert(circle);
    }
    found.into_iter().collect()
}

/// Circles are found whatever their length, each once; a graph without one has none.
#[test]
fn circles_of_any_length_are_found() {
    let graph = |pairs: &[(u8, u8)]| {
        let mut g: BTreeMap<u8, BTreeSet<u8>> = BTreeMap::new();
        for &(a, b) in pairs {
            g.entry(a).or_default().insert(b);
        }
        g
    };
    assert_eq!(circles(&graph(&[(1, 2), (2, 1)])), [vec![1, 2, 1]]);
    assert_eq!(
        circles(&graph(&[(1, 2), (2, 3), (3, 1), (3, 4)])),
        [vec![1, 2, 3, 1]]
    );
    assert!(circles(&graph(&[(1, 2), (2, 3), (1, 3), (3, 4)])).is_empty());
}

/// Paths are read absolute from the file's own module: `super`, `super::super`, groups, and not
/// the file's tests.
#[test]
fn paths_are_read_from_the_files_own_module() {
    let own = ["run".to_owned(), "resume".to_owned()];
    let text = "use super::streams::{Given, Output};\n\
                use crate::output::watch::Target;\n\
                let r: super::super::error::Result<()> = Ok(()); // crate::cli\n\
                #[cfg(test)]\nmod tests {\n    use super::frames::Frames;\n}\n";
    let named: Vec<String> = paths_named(text, &own)
        .iter()
        .map(|p| p.join("::"))
        .collect();
    assert_eq!(
        named,
        [
            "run::streams::Given",
            "run::streams::Output",
            "output::watch::Target",
            "error::Result"
        ]
    );
}
