//! The architecture ARCHITECTURE.md draws is the one the code has: the crate diagram between its
//! `crate-diagram` markers is what `scripts/crate-diagram` makes of `cargo metadata` today, no
//! dependency runs back up, and no two top-level modules of a crate import each other.
//!
//! The diagram's rules, the same as the script's: a crate with no workspace dependency is on
//! layer 0, any other one layer above the highest of its normal workspace dependencies; crates
//! are listed top layer first, then by name, each with its dependencies in the same order and
//! the `voxlod-` prefix dropped; the dev-dependencies follow apart.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

const BEGIN: &str = "<!-- crate-diagram:begin -->";
const END: &str = "<!-- crate-diagram:end -->";

/// The facade: the library a program links.
const FACADE: &str = "voxlod";
/// The crates built on the facade; nothing else may depend on it, and nothing on them but the
/// command line (on `voxlod-eval`).
const ABOVE_FACADE: [&str; 3] = ["voxlod-cli", "voxlod-eval", "voxlod-py"];
/// Test fixtures: a dev-dependency only.
const DEV_ONLY: &str = "voxlod-testkit";

/// A workspace crate: its folder and its workspace dependencies, normal and dev.
struct Crate {
    dir: PathBuf,
    normal: BTreeSet<String>,
    dev: BTreeSet<String>,
}

/// The workspace's crates by name, from `cargo metadata`.
fn workspace() -> BTreeMap<String, Crate> {
    let out = Command::new(env!("CARGO"))
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let meta: Value = serde_json::from_slice(&out.stdout).expect("cargo metadata's JSON");
    let packages = meta["packages"].as_array().expect("packages");
    let names: BTreeSet<&str> = packages.iter().filter_map(|p| p["name"].as_str()).collect();
    let mut crates = BTreeMap::new();
    for p in packages {
        let (mut normal, mut dev) = (BTreeSet::new(), BTreeSet::new());
        for d in p["dependencies"].as_array().expect("dependencies") {
            let name = d["name"].as_str().expect("name");
            if names.contains(name) {
                match d["kind"].as_str() {
                    None => normal.insert(name.to_string()),
                    Some("dev") => dev.insert(name.to_string()),
                    Some(_) => false,
                };
            }
        }
        let manifest = Path::new(p["manifest_path"].as_str().expect("manifest_path"));
        let dir = manifest.parent().expect("a folder").to_path_buf();
        let name = p["name"].as_str().expect("name").to_string();
        crates.insert(name, Crate { dir, normal, dev });
    }
    crates
}

/// Each crate's layer, or the crates of a dependency cycle.
fn layers(crates: &BTreeMap<String, Crate>) -> Result<BTreeMap<&str, usize>, Vec<&str>> {
    fn visit<'a>(
        name: &'a str,
        crates: &'a BTreeMap<String, Crate>,
        layer: &mut BTreeMap<&'a str, usize>,
        path: &mut Vec<&'a str>,
    ) -> Result<usize, Vec<&'a str>> {
        if let Some(&l) = layer.get(name) {
            return Ok(l);
        }
        if let Some(at) = path.iter().position(|&n| n == name) {
            return Err([&path[at..], &[name]].concat());
        }
        path.push(name);
        let mut l = 0;
        for d in &crates[name].normal {
            l = l.max(1 + visit(d, crates, layer, path)?);
        }
        path.pop();
        layer.insert(name, l);
        Ok(l)
    }
    let mut layer = BTreeMap::new();
    for name in crates.keys() {
        visit(name, crates, &mut layer, &mut Vec::new())?;
    }
    Ok(layer)
}

/// The block between the markers, as `scripts/crate-diagram` prints it.
fn diagram(crates: &BTreeMap<String, Crate>) -> String {
    let layer = layers(crates).expect("no dependency cycle");
    let top_down = |names: &mut Vec<&str>| names.sort_by_key(|n| (usize::MAX - layer[n], *n));
    let line = |deps: &BTreeSet<String>| {
        let mut deps: Vec<&str> = deps.iter().map(String::as_str).collect();
        top_down(&mut deps);
        let short: Vec<&str> = deps
            .iter()
            .map(|d| d.strip_prefix("voxlod-").unwrap_or(d))
            .collect();
        if short.is_empty() {
            "-".to_string()
        } else {
            short.join(" ")
        }
    };
    let mut names: Vec<&str> = crates.keys().map(String::as_str).collect();
    top_down(&mut names);
    let w = names.iter().map(|n| n.len()).max().unwrap_or(0);
    let mut text = format!(
        "```text\nlayer  {:<w$}  normal dependencies (`voxlod-` dropped)\n",
        "crate"
    );
    for n in &names {
        text += &format!("{:>5}  {n:<w$}  {}\n", layer[n], line(&crates[*n].normal));
    }
    text += &format!(
        "\n       {:<w$}  dev-dependencies (tests, benches, examples)\n",
        "crate"
    );
    for n in names.iter().filter(|n| !crates[**n].dev.is_empty()) {
        text += &format!("       {n:<w$}  {}\n", line(&crates[*n].dev));
    }
    text + "```\n"
}

#[test]
fn architecture_md_draws_the_crates_as_they_are() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("ARCHITECTURE.md");
    let doc = std::fs::read_to_string(&path).expect("ARCHITECTURE.md");
    let start = doc.find(BEGIN).expect("the begin marker") + BEGIN.len() + 1;
    let end = doc.find(END).expect("the end marker");
    let drawn = doc.get(start..end).unwrap_or_default();
    let wanted = diagram(&workspace());
    assert!(
        drawn == wanted,
        "ARCHITECTURE.md's crate diagram is stale: run scripts/crate-diagram --write\n{wanted}"
    );
}

#[test]
fn no_dependency_runs_back_up() {
    let crates = workspace();
    if let Err(cycle) = layers(&crates) {
        panic!("dependency cycle: {}", cycle.join(" -> "));
    }
    for (name, c) in &crates {
        for d in &c.normal {
            let above = d == FACADE || ABOVE_FACADE.contains(&d.as_str());
            let allowed =
                ABOVE_FACADE.contains(&name.as_str()) && d != "voxlod-cli" && d != "voxlod-py";
            assert!(
                !above || allowed,
                "{name} depends on {d}, which is built on it"
            );
            assert!(
                d != DEV_ONLY,
                "{name} depends on {DEV_ONLY}: fixtures are a dev-dependency only"
            );
        }
    }
}

/// The `.rs` files under `dir`, recursively.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let path = entry.path();
        if path.is_dir() {
            files.extend(rust_files(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            files.push(path);
        }
    }
    files.sort();
    files
}

/// `text` without its comments and without its test module (from `#[cfg(test)] mod` on).
fn code(text: &str) -> String {
    let tests = text.match_indices("#[cfg(test)]").find(|(at, attribute)| {
        text[at + attribute.len()..]
            .trim_start()
            .starts_with("mod ")
    });
    let text = &text[..tests.map_or(text.len(), |(at, _)| at)];
    text.lines()
        .map(|l| l.split("//").next().unwrap_or_default())
        .collect::<Vec<_>>()
        .join("\n")
}

/// The identifier at the start of `s`.
fn ident(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The first segments of the paths of a `{…}` group at the start of `s` (`{a::b, c}`: a, c).
fn group_heads(s: &str) -> Vec<&str> {
    let (mut depth, mut heads, mut at_start) = (0, Vec::new(), true);
    for (i, c) in s.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 1 => break,
            '}' => depth -= 1,
            ',' if depth == 1 => at_start = true,
            c if at_start && depth == 1 && (c.is_alphanumeric() || c == '_') => {
                heads.push(ident(&s[i..]));
                at_start = false;
            }
            _ => {}
        }
    }
    heads
}

/// What the crate root's `use` statements name, by the top-level module they come from.
fn root_names(root: &str, modules: &BTreeSet<String>) -> BTreeMap<String, String> {
    let mut names = BTreeMap::new();
    for statement in code(root).split(';') {
        let Some(path) = statement
            .trim()
            .trim_start_matches("pub ")
            .strip_prefix("use ")
        else {
            continue;
        };
        let path = path
            .trim_start_matches("self::")
            .trim_start_matches("crate::");
        let module = ident(path);
        if !modules.contains(module) {
            continue;
        }
        // The leaves: each identifier not followed by `::` or `as` (an alias is its own leaf).
        let mut rest = path;
        while let Some(start) = rest.find(|c: char| c.is_alphanumeric() || c == '_') {
            let word = ident(&rest[start..]);
            rest = &rest[start + word.len()..];
            let after = rest.trim_start();
            if !["as", "self"].contains(&word)
                && !after.starts_with("::")
                && !after.starts_with("as ")
            {
                names.insert(word.to_string(), module.to_string());
            }
        }
    }
    names
}

/// The top-level modules a file of module `path` (`["a", "b"]` for `src/a/b.rs`) refers to
/// through `crate::…`, or through as many `super::`s as lead to the root.
fn references(
    text: &str,
    path: &[&str],
    modules: &BTreeSet<String>,
    root: &BTreeMap<String, String>,
) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let starts = text
        .match_indices("crate::")
        .chain(text.match_indices("super::"));
    for (at, _) in starts {
        // A path's start only: not `$crate::`, not the second `super::` of `super::super::`.
        let before = text[..at].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || "_$:".contains(c)) {
            continue;
        }
        let (mut tail, mut ups) = (&text[at..], 0);
        while let Some(t) = tail.strip_prefix("super::") {
            (tail, ups) = (t, ups + 1);
        }
        let tail = match tail.strip_prefix("crate::") {
            Some(t) if ups == 0 => t,
            None if ups == path.len() => tail,
            _ => continue,
        };
        let heads = if tail.starts_with('{') {
            group_heads(tail)
        } else {
            vec![ident(tail)]
        };
        for head in heads {
            let called = tail.starts_with(head) && tail[head.len()..].starts_with('(');
            if modules.contains(head) && !called {
                found.insert(head.to_string());
            } else if let Some(module) = root.get(head) {
                found.insert(module.clone());
            }
        }
    }
    found
}

/// A crate's top-level modules, each with the others its files refer to (tests left out).
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let module_path = |file: &Path| -> Vec<String> {
        let relative = file
            .strip_prefix(src)
            .expect("under src")
            .with_extension("");
        let parts = relative.iter().map(|p| p.to_string_lossy().into_owned());
        parts.filter(|p| p != "mod").collect()
    };
    let files: Vec<(PathBuf, Vec<String>)> = rust_files(src)
        .into_iter()
        .map(|f| (module_path(&f), f))
        .filter(|(m, _)| !m.iter().any(|p| p == "tests" || p == "bin"))
        .map(|(m, f)| (f, m))
        .collect();
    let is_root = |m: &[String]| m == ["lib"] || m == ["main"];
    let modules: BTreeSet<String> = files
        .iter()
        .filter(|(_, m)| !is_root(m))
        .map(|(_, m)| m[0].clone())
        .collect();
    let read = |f: &Path| std::fs::read_to_string(f).expect("a source file");
    let root = files
        .iter()
        .find(|(_, m)| is_root(m))
        .map(|(f, _)| read(f))
        .unwrap_or_default();
    let root = root_names(&root, &modules);
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (file, m) in files.iter().filter(|(_, m)| !is_root(m)) {
        let path: Vec<&str> = m.iter().map(String::as_str).collect();
        let mut refs = references(&code(&read(file)), &path, &modules, &root);
        refs.remove(&m[0]);
        graph.entry(m[0].clone()).or_default().extend(refs);
    }
    graph
}

/// The groups of two or more modules that reach each other, each with its edges (`a -> b`).
fn module_cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> BTreeSet<Vec<String>> {
    let reach = |from: &str| {
        let (mut seen, mut todo) = (BTreeSet::new(), vec![from.to_string()]);
        while let Some(m) = todo.pop() {
            for n in graph.get(&m).into_iter().flatten() {
                if seen.insert(n.clone()) {
                    todo.push(n.clone());
                }
            }
        }
        seen
    };
    let reached: BTreeMap<&String, BTreeSet<String>> =
        graph.keys().map(|m| (m, reach(m))).collect();
    let mut cycles = BTreeSet::new();
    for (m, from_m) in &reached {
        let group: BTreeSet<&String> = from_m
            .iter()
            .filter(|n| reached.get(n).is_some_and(|r| r.contains(*m)))
            .collect();
        let edges = group.iter().flat_map(|a| {
            let inside = graph[*a].iter().filter(|b| group.contains(b));
            inside.map(move |b| format!("{a} -> {b}"))
        });
        if group.len() > 1 {
            cycles.insert(edges.collect());
        }
    }
    cycles
}

#[test]
fn no_two_modules_of_a_crate_import_each_other() {
    let mut refused = Vec::new();
    for (name, c) in workspace() {
        for cycle in module_cycles(&module_graph(&c.dir.join("src"))) {
            refused.push(format!("{name}: {}", cycle.join(", ")));
        }
    }
    assert!(
        refused.is_empty(),
        "modules that import each other:\n{}",
        refused.join("\n")
    );
}
