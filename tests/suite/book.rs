//! The book (`docs/book/`) against the code and against itself:
//!
//! - **The scenario reference** (`docs/book/src/scenario-reference.md`) documents exactly the
//!   fields of the scenario file. The scenario types derive `schemars::JsonSchema`; this test
//!   walks the JSON Schema of [`vibrobed::Scenario`] (nested objects, optional fields, lists,
//!   the untagged alternatives of `particles.radius` and `particles.placement`) into one entry
//!   per field path, and reads the reference's field tables (tables whose header starts with
//!   `field | type | default`) into one row per path. A path in the code without a row, or a
//!   row for a path the code does not have, fails. So does a row that leaves out an option of
//!   a string field (`walls`, `periodic`, …), a JSON type the field accepts, or the default the
//!   code uses for a scalar field.
//! - **Internal links** in `README.md` and `docs/book/src/**/*.md` resolve: the linked file
//!   exists, and an `#anchor` names a heading of the target page by the slug rule GitHub and
//!   mdBook share (lower case; letters, digits, `-` and `_` kept; white space to `-`; anything
//!   else dropped; `-1`, `-2`, … for repeated headings).
//! - **The book's structure**: every page is listed in `SUMMARY.md`, and no page uses
//!   mdBook-only syntax (`{{#include …}}` and the like), so that every page reads on GitHub too.

use pulldown_cmark::{Event, Options, Parser, Tag, TagEnd};
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Component, Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn book_src() -> PathBuf {
    root().join("docs/book/src")
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

fn markdown_options() -> Options {
    Options::ENABLE_TABLES | Options::ENABLE_FOOTNOTES | Options::ENABLE_STRIKETHROUGH
}

/// Line number (from 1) of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

// ---------------------------------------------------------------------------------------------
// The scenario's fields, from its JSON Schema.

/// What the schema says about one field.
#[derive(Debug, Default)]
struct SchemaField {
    /// JSON types it accepts, in the reference's words: number, integer, string, boolean,
    /// object, list (`null` left out: it only marks an optional field).
    types: BTreeSet<&'static str>,
    /// The values of a string field with a fixed set of options.
    options: BTreeSet<String>,
    /// The default the code fills in, when the schema states one.
    default: Option<Value>,
}

/// The schema node `node` refers to (through `$ref`), or `node` itself.
fn resolve<'a>(schema: &'a Value, node: &'a Value) -> &'a Value {
    match node.get("$ref").and_then(Value::as_str) {
        Some(reference) => {
            let name = reference
                .rsplit('/')
                .next()
                .expect("a $ref names a definition");
            let defs = schema
                .get("$defs")
                .or_else(|| schema.get("definitions"))
                .expect("the schema holds its definitions");
            let target = defs
                .get(name)
                .unwrap_or_else(|| panic!("no definition {name} in the schema"));
            resolve(schema, target)
        }
        None => node,
    }
}

/// Collects into `field` what schema node `node` accepts, and into `children` the properties of
/// the objects it accepts (for a list of objects, the properties of its items, as `[]` paths).
fn describe(
    schema: &Value,
    node: &Value,
    field: &mut SchemaField,
    children: &mut Vec<(String, Value)>,
    prefix: &str,
) {
    let node = resolve(schema, node);
    for key in ["anyOf", "oneOf", "allOf"] {
        if let Some(branches) = node.get(key).and_then(Value::as_array) {
            for branch in branches {
                describe(schema, branch, field, children, prefix);
            }
        }
    }
    let mut types: Vec<&str> = match node.get("type") {
        Some(Value::String(t)) => vec![t.as_str()],
        Some(Value::Array(ts)) => ts.iter().filter_map(Value::as_str).collect(),
        _ => Vec::new(),
    };
    if types.is_empty() && node.get("properties").is_some() {
        types.push("object");
    }
    for value in node
        .get("enum")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .chain(node.get("const"))
    {
        if let Some(option) = value.as_str() {
            field.options.insert(option.to_string());
            types.push("string");
        }
    }
    for t in types {
        let word = match t {
            "null" => continue,
            "number" => "number",
            "integer" => "integer",
            "string" => "string",
            "boolean" => "boolean",
            "object" => "object",
            "array" => "list",
            other => panic!("a scenario field of JSON type {other}: teach tests/book.rs its word"),
        };
        field.types.insert(word);
    }
    if let Some(properties) = node.get("properties").and_then(Value::as_object) {
        for (name, property) in properties {
            children.push((format!("{prefix}.{name}"), property.clone()));
        }
    }
    if let Some(items) = node.get("items") {
        // The items of a list: fields of its objects are named `list[].field`.
        let mut item = SchemaField::default();
        let mut item_children = Vec::new();
        describe(
            schema,
            items,
            &mut item,
            &mut item_children,
            &format!("{prefix}[]"),
        );
        children.extend(item_children);
    }
}

/// Every field path of the scenario file, as the schema gives them (the fuzzers' lists are
/// checked against it too).
pub(crate) fn scenario_field_paths() -> Vec<String> {
    schema_fields().into_keys().collect()
}

/// Every field path of the scenario file, with what the schema says about it.
fn schema_fields() -> BTreeMap<String, SchemaField> {
    let schema = serde_json::to_value(schemars::schema_for!(vibrobed::Scenario))
        .expect("the schema serialises");
    let mut fields = BTreeMap::new();
    let mut stack: Vec<(String, Value)> = Vec::new();
    let mut top = SchemaField::default();
    describe(&schema, &schema, &mut top, &mut stack, "");
    while let Some((path, node)) = stack.pop() {
        let path = path.trim_start_matches('.').to_string();
        let mut field = SchemaField {
            default: node.get("default").cloned(),
            ..SchemaField::default()
        };
        let mut children = Vec::new();
        describe(&schema, &node, &mut field, &mut children, &path);
        stack.extend(children);
        assert!(
            fields.insert(path.clone(), field).is_none(),
            "the schema walk met {path} twice"
        );
    }
    fields
}

// ---------------------------------------------------------------------------------------------
// The reference's rows.

/// One cell of a table: its plain text and its code spans.
#[derive(Debug, Default, Clone)]
struct Cell {
    text: String,
    code: Vec<String>,
}

impl Cell {
    /// The cell's words: its code spans, and its text split at anything but letters, digits and
    /// `.`, `-`, `_`, `+` (so that `1`, `0.5`, `1e-3` and `event-driven` stay whole).
    fn words(&self) -> BTreeSet<String> {
        let mut words: BTreeSet<String> = self.code.iter().cloned().collect();
        for word in self
            .text
            .split(|c: char| !(c.is_alphanumeric() || matches!(c, '.' | '-' | '_' | '+')))
        {
            let word = word.trim_end_matches('.');
            if !word.is_empty() {
                words.insert(word.to_string());
            }
        }
        words
    }
}

/// A documented field: the line of its row and the row's cells (field, type, default, meaning).
#[derive(Debug)]
struct Row {
    line: usize,
    cells: Vec<Cell>,
}

/// Whether `s` is a field path: `name(.name)*`, each name lower case with `_`, optionally `[]`.
fn is_field_path(s: &str) -> bool {
    !s.is_empty()
        && s.split('.').all(|part| {
            let name = part.strip_suffix("[]").unwrap_or(part);
            !name.is_empty()
                && name
                    .chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
        })
}

/// The rows of the field tables of a Markdown page: tables whose header begins with
/// `field | type | default`, keyed by the field path in the first cell's code span.
fn reference_rows(text: &str) -> (BTreeMap<String, Row>, Vec<String>) {
    let mut rows = BTreeMap::new();
    let mut problems = Vec::new();
    let mut in_head = false;
    let mut field_table = false;
    let mut row: Vec<Cell> = Vec::new();
    let mut cell: Option<Cell> = None;
    let mut row_start = 0;
    for (event, range) in Parser::new_ext(text, markdown_options()).into_offset_iter() {
        match event {
            Event::Start(Tag::Table(_)) => field_table = false,
            Event::Start(Tag::TableHead) => {
                in_head = true;
                row.clear();
                row_start = range.start;
            }
            Event::Start(Tag::TableRow) => {
                row.clear();
                row_start = range.start;
            }
            Event::Start(Tag::TableCell) => cell = Some(Cell::default()),
            Event::Text(t) => {
                if let Some(c) = cell.as_mut() {
                    c.text.push_str(&t);
                }
            }
            Event::Code(t) => {
                if let Some(c) = cell.as_mut() {
                    c.code.push(t.to_string());
                    c.text.push(' ');
                }
            }
            Event::End(TagEnd::TableCell) => row.extend(cell.take()),
            Event::End(TagEnd::TableHead) => {
                in_head = false;
                let head: Vec<String> = row.iter().map(|c| c.text.trim().to_lowercase()).collect();
                field_table = head.len() >= 4 && head[..3] == ["field", "type", "default"];
            }
            Event::End(TagEnd::TableRow) if field_table && !in_head => {
                let line = line_of(text, row_start);
                let first = &row[0];
                let path = match first.code.as_slice() {
                    [path] if first.text.trim().is_empty() && is_field_path(path) => path.clone(),
                    _ => {
                        problems.push(format!(
                            "scenario-reference.md:{line}: a field table's row must start with \
                             one field path in a code span (got {:?})",
                            first.text
                        ));
                        continue;
                    }
                };
                let previous = rows.insert(
                    path.clone(),
                    Row {
                        line,
                        cells: row.clone(),
                    },
                );
                if let Some(previous) = previous {
                    problems.push(format!(
                        "scenario-reference.md:{line}: `{path}` is documented twice (also line {})",
                        previous.line
                    ));
                }
            }
            _ => {}
        }
    }
    (rows, problems)
}

/// Whether a default cell's words show the default `value` the code uses.
fn shows_default(words: &BTreeSet<String>, value: &Value) -> bool {
    match value {
        Value::Bool(b) => words.contains(&b.to_string()),
        Value::String(s) => words.contains(s),
        Value::Number(n) => {
            let n = n.as_f64().expect("a finite default");
            words.iter().any(|w| w.parse::<f64>().is_ok_and(|x| x == n))
        }
        _ => true, // objects and lists (a whole section's defaults) are described in words
    }
}

#[test]
fn the_scenario_reference_documents_every_field_and_only_those() {
    let page = book_src().join("scenario-reference.md");
    let text = read(&page);
    let fields = schema_fields();
    let (rows, mut problems) = reference_rows(&text);
    assert!(
        fields.len() > 50 && rows.len() > 50,
        "the walk found {} fields in the schema and {} rows in the reference: too few, the \
         test has lost its grip",
        fields.len(),
        rows.len()
    );
    for (path, field) in &fields {
        let Some(row) = rows.get(path) else {
            problems.push(format!(
                "`{path}` is a scenario field (src/scenario/) that scenario-reference.md does \
                 not document: add a row `| `{path}` | type | default | meaning and constraints |`"
            ));
            continue;
        };
        let line = row.line;
        if row.cells.len() < 4 {
            problems.push(format!(
                "scenario-reference.md:{line}: `{path}` needs four cells (field, type, default, meaning)"
            ));
            continue;
        }
        let types = row.cells[1].words();
        for t in &field.types {
            if !types.contains(*t) {
                problems.push(format!(
                    "scenario-reference.md:{line}: `{path}` accepts a JSON {t}; its type cell \
                     says {:?}",
                    row.cells[1].text.trim()
                ));
            }
        }
        let all: BTreeSet<String> = row.cells.iter().flat_map(|c| c.code.clone()).collect();
        for option in &field.options {
            if !all.contains(option) {
                problems.push(format!(
                    "scenario-reference.md:{line}: `{path}` takes `{option}`, which its row \
                     does not name (in a code span)"
                ));
            }
        }
        if let Some(default) = &field.default {
            if !shows_default(&row.cells[2].words(), default) {
                problems.push(format!(
                    "scenario-reference.md:{line}: `{path}` defaults to {default} in the code; \
                     its default cell says {:?}",
                    row.cells[2].text.trim()
                ));
            }
        }
    }
    for (path, row) in &rows {
        if !fields.contains_key(path) {
            problems.push(format!(
                "scenario-reference.md:{}: `{path}` is documented but is not a scenario field",
                row.line
            ));
        }
    }
    assert!(
        problems.is_empty(),
        "the scenario reference and the scenario types differ:\n{}",
        problems.join("\n")
    );
}

// ---------------------------------------------------------------------------------------------
// Links.

/// The Markdown files whose links are checked: the README and every page of the book.
fn markdown_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
            .map(|e| e.expect("a directory entry").path())
            .collect();
        entries.sort();
        for path in entries {
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|x| x == "md") {
                out.push(path);
            }
        }
    }
    let mut files = vec![root().join("README.md")];
    walk(&book_src(), &mut files);
    files
}

/// The anchor a heading gets on GitHub and in mdBook: lower case; letters, digits, `-` and `_`
/// kept; white space to `-`; anything else dropped.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| {
            if c.is_alphanumeric() || c == '-' || c == '_' {
                Some(c)
            } else if c.is_whitespace() {
                Some('-')
            } else {
                None
            }
        })
        .collect()
}

/// A page's anchors: its headings' slugs, a repeated slug numbered `-1`, `-2`, ….
fn anchors(text: &str) -> BTreeSet<String> {
    let mut anchors = BTreeSet::new();
    let mut heading: Option<String> = None;
    for event in Parser::new_ext(text, markdown_options()) {
        match event {
            Event::Start(Tag::Heading { .. }) => heading = Some(String::new()),
            Event::Text(t) | Event::Code(t) => {
                if let Some(h) = heading.as_mut() {
                    h.push_str(&t);
                }
            }
            Event::End(TagEnd::Heading(_)) => {
                let base = slug(&heading.take().unwrap_or_default());
                let mut candidate = base.clone();
                let mut k = 0;
                while !anchors.insert(candidate.clone()) {
                    k += 1;
                    candidate = format!("{base}-{k}");
                }
            }
            _ => {}
        }
    }
    anchors
}

/// Every link and image target of a page, with its line.
fn links(text: &str) -> Vec<(usize, String)> {
    Parser::new_ext(text, markdown_options())
        .into_offset_iter()
        .filter_map(|(event, range)| match event {
            Event::Start(Tag::Link { dest_url, .. })
            | Event::Start(Tag::Image { dest_url, .. }) => {
                Some((line_of(text, range.start), dest_url.to_string()))
            }
            _ => None,
        })
        .collect()
}

/// `path` with `.` and `..` taken out (without touching the file system).
fn normalise(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// Whether a link leaves the repository's files: a web address, a mail address.
fn is_external(target: &str) -> bool {
    target.contains("://") || target.starts_with("mailto:")
}

#[test]
fn every_internal_link_resolves() {
    let mut cache: HashMap<PathBuf, BTreeSet<String>> = HashMap::new();
    let mut problems = Vec::new();
    let files = markdown_files();
    assert!(
        files.len() > 20,
        "only {} Markdown files found",
        files.len()
    );
    for file in &files {
        let text = read(file);
        let shown = file
            .strip_prefix(root())
            .unwrap_or(file)
            .display()
            .to_string();
        for (line, target) in links(&text) {
            if is_external(&target) {
                continue;
            }
            let (path, anchor) = match target.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (target.as_str(), None),
            };
            if path.starts_with('/') {
                problems.push(format!(
                    "{shown}:{line}: {target}: an absolute path; link relative to the page"
                ));
                continue;
            }
            let resolved = if path.is_empty() {
                file.clone()
            } else {
                normalise(&file.parent().expect("a file has a folder").join(path))
            };
            if !resolved.exists() {
                problems.push(format!("{shown}:{line}: {target}: no such file"));
                continue;
            }
            let Some(anchor) = anchor else { continue };
            if resolved.extension().is_none_or(|x| x != "md") {
                problems.push(format!(
                    "{shown}:{line}: {target}: an anchor into a file that is not Markdown"
                ));
                continue;
            }
            let known = cache
                .entry(resolved.clone())
                .or_insert_with(|| anchors(&read(&resolved)));
            if !known.contains(anchor) {
                problems.push(format!(
                    "{shown}:{line}: {target}: no heading with the anchor #{anchor} in {}",
                    resolved.strip_prefix(root()).unwrap_or(&resolved).display()
                ));
            }
        }
    }
    assert!(
        problems.is_empty(),
        "broken internal links:\n{}",
        problems.join("\n")
    );
}

#[test]
fn the_slug_rule_matches_github_and_mdbook() {
    assert_eq!(
        slug("Trajectories (extended XYZ)"),
        "trajectories-extended-xyz"
    );
    assert_eq!(
        slug("What each effect costs (`--effects`)"),
        "what-each-effect-costs---effects"
    );
    assert_eq!(
        slug("The approximate schemes' summary"),
        "the-approximate-schemes-summary"
    );
    assert_eq!(slug("`domain`"), "domain");
    let text = "# A\n\n## B\n\n## B\n\n### Γ ≫ 10\n";
    let expected: BTreeSet<String> = ["a", "b", "b-1", "γ--10"].map(String::from).into();
    assert_eq!(anchors(text), expected);
}

// ---------------------------------------------------------------------------------------------
// The book's structure.

#[test]
fn every_page_is_in_the_summary_and_reads_on_github() {
    let src = book_src();
    let summary = read(&src.join("SUMMARY.md"));
    let listed: BTreeSet<PathBuf> = links(&summary)
        .into_iter()
        .map(|(_, target)| normalise(&src.join(target)))
        .collect();
    let mut problems = Vec::new();
    for file in markdown_files() {
        let text = read(&file);
        let shown = file
            .strip_prefix(root())
            .unwrap_or(&file)
            .display()
            .to_string();
        if text.contains("{{#") {
            problems.push(format!(
                "{shown}: uses mdBook-only syntax ({{{{#…}}}}), which GitHub shows as is"
            ));
        }
        if file.starts_with(&src) && !file.ends_with("SUMMARY.md") && !listed.contains(&file) {
            problems.push(format!(
                "{shown}: not listed in docs/book/src/SUMMARY.md (mdBook leaves it out)"
            ));
        }
    }
    for page in &listed {
        if !page.exists() {
            problems.push(format!(
                "SUMMARY.md lists {}, which does not exist",
                page.display()
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The names in backticks of the contributing page's engine table (from its lead-in to the
/// next heading).
fn engine_table_names() -> BTreeSet<String> {
    let page = read(&book_src().join("contributing.md"));
    let start = page
        .find("The engine, `engine/`, reads by concept")
        .expect("the contributing page has the engine's table");
    let table = &page[start..];
    let table = &table[..table.find("\n## ").unwrap_or(table.len())];
    table
        .split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// The name the engine table gives a file or folder of `src/engine` at `depth` (0: directly in
/// it): `name.rs` and `name/` at the top, a folder's files by their stem and its folders as
/// `name/` below.
fn engine_entries(dir: &Path, depth: usize, out: &mut Vec<String>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|e| e.expect("a directory entry").path())
        .collect();
    entries.sort();
    for path in entries {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if path.is_dir() {
            out.push(format!("{name}/"));
            engine_entries(&path, depth + 1, out);
        } else if name == "mod.rs" && depth > 0 {
            continue;
        } else if depth == 0 {
            out.push(name);
        } else {
            out.push(name.trim_end_matches(".rs").to_string());
        }
    }
}

/// The contributing page's engine table names every file and folder of `src/engine`, so that
/// a newcomer finds each in it.
#[test]
fn the_engine_table_names_every_engine_file() {
    let named = engine_table_names();
    let mut entries = Vec::new();
    engine_entries(&root().join("src/engine"), 0, &mut entries);
    assert!(entries.len() > 20, "{entries:?}");
    let missing: Vec<_> = entries.iter().filter(|e| !named.contains(*e)).collect();
    assert!(
        missing.is_empty(),
        "the engine table of docs/book/src/contributing.md does not name {missing:?}"
    );
}
