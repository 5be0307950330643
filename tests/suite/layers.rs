//! The crate's layers against its imports: `src/lib.rs` lists the layers from the bottom up (one
//! `- [`module`]` line each), the book's contributing page lists the same in its code-layout
//! table, and no module of `src/` names (`crate::…`, outside comments) a module above its own.
//! A new top-level module must be placed in both lists.

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
