//! The architecture of docs/architecture.md, checked on the source text under `src/`.
//!
//! granflow is one crate built as two storeys, with the binary on top:
//!
//! * the **physics** storey: the base helpers (`scale`, `units`, `error`, `analysis`,
//!   `report`, `exec`), the three solvers (`lbm`, `dem`, `mpm`) and `coupling`, which links
//!   them. It knows nothing of files or the command line;
//! * the **scenario** storey: `scenario` (the file of each kind, its runner, bench and
//!   validation cases), `sweep` (studies over many scenarios) and the output writers `io`;
//! * the **binary**: `src/main.rs` and `src/cli/`, which the library never sees.
//!
//! A *room* is a top-level module of the library (`src/X.rs` or `src/X/`); the crate-root
//! names `crate::Error` and `crate::Result` belong to `error`. A *reference* is a `crate::…`,
//! `super::…` or `self::…` path in code (a `use` line, expanded group by group, or a path
//! inline in an expression or a type), found after comments, doc comments and the contents of
//! string literals are blanked out, so doc links do not count. The rules, one `#[test]` each:
//!
//! 1. a base helper references only base helpers;
//! 2. a solver (`lbm`, `dem`, `mpm`) references only base helpers: never another solver,
//!    `coupling`, `scenario`, `sweep` or `io`;
//! 3. `coupling` references base helpers and the solvers;
//! 4. `io` references only base helpers;
//! 5. `scenario` references anything in the library but `sweep`;
//! 6. `sweep` references anything in the library;
//! 7. the library never references the CLI (no `crate::cli`, no `mod cli` outside the binary);
//! 8. there is no import cycle between files of the library (code under `#[cfg(test)]` is
//!    left out of this one only: a solver's tests may build a packing that uses the solver);
//! 9. no file under `src/` is longer than 800 lines unless its head comment has a
//!    `//! Length:` line saying why.
//!
//! A reference is resolved to a file: `crate::a::b::C` goes to the deepest module file that
//! exists (`src/a/b.rs` or `src/a/b/mod.rs`), and a name that a module re-exports
//! (`pub use child::{A, B}`, `pub use child::*`) is followed to the file that defines it, so
//! `crate::dem::Grains` is `src/dem/grains.rs`, not `src/dem/mod.rs`. A module's relative
//! paths into its own children (`pub use spec::*;`, `use forces::…;`) are not references: a
//! module and the children it declares are one unit seen from outside, and its `pub use`
//! lines are what the resolution follows. `mod x;` declarations are not references either.
//!
//! The test uses the standard library only and reads the files: it does not link granflow.

use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::path::Path;
use std::sync::OnceLock;

/// Base helpers: the ground floor of the physics storey.
const BASE: &[&str] = &["scale", "units", "error", "analysis", "report", "exec"];
/// The three solvers.
const SOLVERS: &[&str] = &["lbm", "dem", "mpm"];
/// Every room of the library, both storeys.
const LIBRARY: &[&str] = &[
    "scale", "units", "error", "analysis", "report", "exec", "lbm", "dem", "mpm", "coupling", "io",
    "scenario", "sweep",
];
/// Longest file allowed without a `//! Length:` line in its head comment.
const MAX_LINES: usize = 800;

// ---------------------------------------------------------------------------------------------
// Lexing: blank out comments and literals, then split into tokens with their line numbers.
// ---------------------------------------------------------------------------------------------

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The source with comments (line, doc and nested block comments) and the contents of string,
/// raw string and char literals removed. Newlines are kept, so line numbers stay right.
fn strip(src: &str) -> String {
    let c: Vec<char> = src.chars().collect();
    let at = |k: usize| c.get(k).copied().unwrap_or('\0');
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    // Skip to `end` (exclusive), keeping only the newlines.
    let keep_newlines = |out: &mut String, from: usize, to: usize| {
        for &ch in &c[from..to.min(c.len())] {
            if ch == '\n' {
                out.push('\n');
            }
        }
    };
    while i < c.len() {
        let ch = c[i];
        if ch == '/' && at(i + 1) == '/' {
            let mut j = i;
            while j < c.len() && c[j] != '\n' {
                j += 1;
            }
            i = j;
        } else if ch == '/' && at(i + 1) == '*' {
            let (mut depth, mut j) = (1, i + 2);
            while j < c.len() && depth > 0 {
                if c[j] == '/' && at(j + 1) == '*' {
                    depth += 1;
                    j += 2;
                } else if c[j] == '*' && at(j + 1) == '/' {
                    depth -= 1;
                    j += 2;
                } else {
                    j += 1;
                }
            }
            keep_newlines(&mut out, i, j);
            out.push(' ');
            i = j;
        } else if ch == 'r'
            && (at(i + 1) == '"' || at(i + 1) == '#')
            && (i == 0
                || !is_ident(c[i - 1])
                || (c[i - 1] == 'b' && (i < 2 || !is_ident(c[i - 2]))))
            && {
                let mut j = i + 1;
                while at(j) == '#' {
                    j += 1;
                }
                at(j) == '"'
            }
        {
            // Raw string r"…", r#"…"#, br"…".
            let mut j = i + 1;
            let mut hashes = 0;
            while at(j) == '#' {
                hashes += 1;
                j += 1;
            }
            j += 1; // the opening quote
            let start = j;
            loop {
                if j >= c.len() {
                    break;
                }
                if c[j] == '"' && (1..=hashes).all(|h| at(j + h) == '#') {
                    break;
                }
                j += 1;
            }
            keep_newlines(&mut out, start, j);
            out.push_str("\"\"");
            i = (j + 1 + hashes).min(c.len());
        } else if ch == '"' {
            let mut j = i + 1;
            while j < c.len() && c[j] != '"' {
                j += if c[j] == '\\' { 2 } else { 1 };
            }
            keep_newlines(&mut out, i, j);
            out.push_str("\"\"");
            i = j + 1;
        } else if ch == '\'' && at(i + 1) == '\\' {
            // Escaped char literal: '\n', '\'', '\u{..}'.
            let mut j = i + 3;
            while j < c.len() && c[j] != '\'' {
                j += 1;
            }
            out.push_str("' '");
            i = j + 1;
        } else if ch == '\'' && at(i + 2) == '\'' && at(i + 1) != '\n' {
            out.push_str("' '");
            i += 3;
        } else {
            // Code, or the quote of a lifetime / label.
            out.push(ch);
            i += 1;
        }
    }
    out
}

#[derive(Clone, Debug)]
struct Tok {
    text: String,
    line: usize,
}

/// Tokens of stripped source: words (identifiers, keywords, numbers), `::`, and single
/// punctuation characters.
fn tokenize(stripped: &str) -> Vec<Tok> {
    let c: Vec<char> = stripped.chars().collect();
    let mut toks = Vec::new();
    let (mut i, mut line) = (0, 1);
    while i < c.len() {
        let start = i;
        i += 1;
        if c[start] == '\n' {
            line += 1;
            continue;
        } else if c[start].is_whitespace() {
            continue;
        } else if is_ident(c[start]) {
            while i < c.len() && is_ident(c[i]) {
                i += 1;
            }
        } else if c[start] == ':' && c.get(i) == Some(&':') {
            i += 1;
        }
        toks.push(Tok {
            text: c[start..i].iter().collect(),
            line,
        });
    }
    toks
}

// ---------------------------------------------------------------------------------------------
// Use trees: `use a::{b::{c, d as e}, f::*, self};` → one leaf per imported path.
// ---------------------------------------------------------------------------------------------

#[derive(Clone, Debug)]
struct UseLeaf {
    /// Segments as written (`crate`, `super`, `self` kept), `self` leaves folded into their
    /// prefix. An empty first segment marks a leading `::` (an extern crate).
    segs: Vec<String>,
    glob: bool,
    /// The name the leaf brings into scope (its alias, or its last segment).
    name: Option<String>,
    line: usize,
}

fn tok(t: &[Tok], i: usize) -> &str {
    t.get(i).map_or("", |t| t.text.as_str())
}

fn parse_use_tree(t: &[Tok], i: &mut usize, prefix: &[String], out: &mut Vec<UseLeaf>) {
    let mut segs = prefix.to_vec();
    let mut line = t.get(*i).map_or(0, |t| t.line);
    loop {
        match tok(t, *i) {
            "" | ";" => return,
            "{" => {
                *i += 1;
                loop {
                    match tok(t, *i) {
                        "}" => {
                            *i += 1;
                            return;
                        }
                        "" | ";" => return,
                        "," => *i += 1,
                        _ => parse_use_tree(t, i, &segs, out),
                    }
                }
            }
            "*" => {
                *i += 1;
                out.push(UseLeaf {
                    segs,
                    glob: true,
                    name: None,
                    line,
                });
                return;
            }
            "::" => {
                // Only a leading `::` reaches here (an extern crate path).
                if segs.is_empty() {
                    segs.push(String::new());
                }
                *i += 1;
            }
            word => {
                line = t[*i].line;
                segs.push(word.to_string());
                *i += 1;
                if tok(t, *i) == "::" {
                    *i += 1;
                    continue;
                }
                if segs.len() > 1 && segs.last().map(String::as_str) == Some("self") {
                    segs.pop();
                }
                let mut name = segs.last().cloned();
                if tok(t, *i) == "as" {
                    name = Some(tok(t, *i + 1).to_string());
                    *i += 2;
                }
                out.push(UseLeaf {
                    segs,
                    glob: false,
                    name,
                    line,
                });
                return;
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The source tree: every file's module path, references, re-exports and public items.
// ---------------------------------------------------------------------------------------------

#[derive(Clone, Debug)]
struct Ref {
    line: usize,
    /// The path as written (a use group expanded), e.g. `crate::lbm::d2q9::CX`.
    text: String,
    /// The absolute module path it names, `crate`/`super`/`self` resolved.
    abs: Vec<String>,
    /// Inside a `#[cfg(test)]` item.
    in_test: bool,
}

#[derive(Debug, Default)]
struct FileInfo {
    /// Path relative to the crate root, e.g. `src/dem/solver/mod.rs`.
    rel: String,
    /// Module path, e.g. `["dem", "solver"]`; empty for `lib.rs` and `main.rs`.
    module: Vec<String>,
    /// `src/main.rs` or a file under `src/cli/`: the binary, a crate of its own.
    binary: bool,
    lines: usize,
    /// Its head comment has a `//! Length:` line.
    says_length: bool,
    refs: Vec<Ref>,
    /// `pub use` (or `pub(crate) use`) at file level: name → absolute path it stands for.
    reexports: BTreeMap<String, Vec<String>>,
    /// `pub use path::*` at file level: the absolute paths re-exported whole.
    glob_reexports: Vec<Vec<String>>,
    /// Names of the items defined at file level with a `pub` visibility.
    pub_items: BTreeSet<String>,
    /// Lines of `mod cli` declarations.
    mod_cli: Vec<usize>,
}

struct Tree {
    files: Vec<FileInfo>,
    /// Library module path → index in `files`.
    modules: BTreeMap<Vec<String>, usize>,
}

/// Module path of a library file from its path under `src/` (`dem/solver/mod.rs` →
/// `[dem, solver]`, `lib.rs` → `[]`).
fn module_of(rel_in_src: &str) -> Vec<String> {
    let trimmed = rel_in_src.trim_end_matches(".rs");
    let mut parts: Vec<String> = trimmed.split('/').map(str::to_string).collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// Marks the tokens of every item carrying `#[cfg(test)]`: from the attribute to the `;` or
/// the matching `}` of the item. (A test module in a file of its own, `#[cfg(test)] mod x;`,
/// is not followed into its file, whose references then count in full; the crate has none.)
fn test_mask(t: &[Tok]) -> Vec<bool> {
    let mut mask = vec![false; t.len()];
    let words = |i: usize, w: &[&str]| w.iter().enumerate().all(|(k, s)| tok(t, i + k) == *s);
    let mut i = 0;
    while i < t.len() {
        if words(i, &["#", "[", "cfg", "(", "test", ")", "]"]) {
            let start = i;
            let mut j = i + 7;
            let mut depth = 0usize;
            while j < t.len() {
                match tok(t, j) {
                    "{" => depth += 1,
                    "}" => {
                        depth = depth.saturating_sub(1);
                        if depth == 0 {
                            break;
                        }
                    }
                    ";" if depth == 0 => break,
                    _ => {}
                }
                j += 1;
            }
            for m in &mut mask[start..=j.min(t.len() - 1)] {
                *m = true;
            }
            i = j + 1;
        } else {
            i += 1;
        }
    }
    mask
}

/// Analyses one file. `modules` is the set of library module paths (for relative use paths).
fn analyse(
    rel: &str,
    text: &str,
    module: Vec<String>,
    binary: bool,
    modules: &BTreeSet<Vec<String>>,
) -> FileInfo {
    let lines = text.lines().count();
    let says_length = text
        .lines()
        .map(str::trim)
        .take_while(|l| l.starts_with("//!") || l.is_empty())
        .any(|l| l.starts_with("//! Length:"));
    let t = tokenize(&strip(text));
    let in_test = test_mask(&t);
    let mut info = FileInfo {
        rel: rel.to_string(),
        module,
        binary,
        lines,
        says_length,
        ..Default::default()
    };

    // Brace depth and the inline modules (`mod tests { … }`) open at each token.
    let mut depth = 0usize;
    let mut inline: Vec<(String, usize)> = Vec::new();
    let mut pending_mod: Option<String> = None;
    let mut i = 0;
    while i < t.len() {
        let w = tok(&t, i);
        let prev = |back: usize| tok(&t, i.wrapping_sub(back));
        let here = || -> Vec<String> {
            info.module
                .iter()
                .cloned()
                .chain(inline.iter().map(|(n, _)| n.clone()))
                .collect()
        };
        match w {
            "{" => {
                depth += 1;
                if let Some(name) = pending_mod.take() {
                    inline.push((name, depth));
                }
            }
            "}" => {
                if inline.last().is_some_and(|(_, d)| *d == depth) {
                    inline.pop();
                }
                depth = depth.saturating_sub(1);
            }
            ";" => pending_mod = None,
            "mod" if prev(1) != "::" && i + 1 < t.len() => {
                let name = tok(&t, i + 1).to_string();
                if name == "cli" {
                    info.mod_cli.push(t[i].line);
                }
                pending_mod = Some(name);
            }
            "pub" if depth == 0 && inline.is_empty() => {
                // A file-level public item: pub [(crate)] [const|unsafe|async] fn|struct|… NAME
                let mut j = i + 1;
                if tok(&t, j) == "(" {
                    while j < t.len() && tok(&t, j) != ")" {
                        j += 1;
                    }
                    j += 1;
                }
                loop {
                    match tok(&t, j) {
                        "unsafe" | "async" | "extern" | "\"" => j += 1,
                        "const" if matches!(tok(&t, j + 1), "fn" | "unsafe" | "async") => j += 1,
                        "fn" | "struct" | "enum" | "trait" | "type" | "mod" | "union" | "const"
                        | "static" => {
                            let mut k = j + 1;
                            if tok(&t, k) == "mut" {
                                k += 1;
                            }
                            info.pub_items.insert(tok(&t, k).to_string());
                            break;
                        }
                        _ => break,
                    }
                }
            }
            "use" => {
                // `pub use` / `pub(crate) use` at file level re-exports.
                let public =
                    prev(1) == "pub" || (prev(1) == ")" && prev(3) == "(" && prev(4) == "pub");
                let reexport = public && depth == 0 && inline.is_empty();
                let here = here();
                let mut j = i + 1;
                let mut leaves = Vec::new();
                parse_use_tree(&t, &mut j, &[], &mut leaves);
                for leaf in leaves {
                    let Some((abs, explicit)) = absolute(&leaf.segs, &here, modules) else {
                        continue; // an extern crate
                    };
                    if explicit {
                        let mut text = leaf.segs.join("::");
                        if leaf.glob {
                            text.push_str("::*");
                        }
                        info.refs.push(Ref {
                            line: leaf.line,
                            text,
                            abs: abs.clone(),
                            in_test: in_test[i],
                        });
                    }
                    if reexport {
                        if leaf.glob {
                            info.glob_reexports.push(abs);
                        } else if let Some(name) = leaf.name {
                            info.reexports.insert(name, abs);
                        }
                    }
                }
                while j < t.len() && tok(&t, j) != ";" {
                    j += 1;
                }
                i = j + 1;
                continue;
            }
            "crate" | "super" | "self" if tok(&t, i + 1) == "::" && prev(1) != "::" => {
                // An inline path: crate::a::b(…), super::super::x::Y, …
                let mut segs = vec![w.to_string()];
                let mut j = i + 1;
                while tok(&t, j) == "::"
                    && t.get(j + 1).is_some_and(|n| n.text.starts_with(is_ident))
                {
                    segs.push(tok(&t, j + 1).to_string());
                    j += 2;
                }
                if let Some((abs, _)) = absolute(&segs, &here(), modules) {
                    info.refs.push(Ref {
                        line: t[i].line,
                        text: segs.join("::"),
                        abs,
                        in_test: in_test[i],
                    });
                }
                i = j;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    info
}

/// The absolute module path of `segs` seen from module `here`, and whether it was written
/// explicitly (`crate::`, `super::`, `self::`) rather than relative to a child module. `None`
/// for an extern crate path.
fn absolute(
    segs: &[String],
    here: &[String],
    modules: &BTreeSet<Vec<String>>,
) -> Option<(Vec<String>, bool)> {
    let first = segs.first()?.as_str();
    match first {
        "crate" => Some((segs[1..].to_vec(), true)),
        "self" => Some((here.iter().chain(&segs[1..]).cloned().collect(), true)),
        "super" => {
            let ups = segs.iter().take_while(|s| *s == "super").count();
            let base = &here[..here.len().saturating_sub(ups)];
            Some((base.iter().chain(&segs[ups..]).cloned().collect(), true))
        }
        "" => None,
        _ => {
            let mut child = here.to_vec();
            child.push(first.to_string());
            modules
                .contains(&child)
                .then(|| (here.iter().chain(segs).cloned().collect(), false))
        }
    }
}

impl Tree {
    /// Builds the tree from `(path relative to the crate root, text)` pairs.
    fn from_sources(sources: &[(String, String)]) -> Tree {
        let mut entries = Vec::new();
        for (rel, text) in sources {
            let in_src = rel.strip_prefix("src/").expect("a file under src/");
            let binary = in_src == "main.rs" || in_src.starts_with("cli/");
            entries.push((rel, text, module_of(in_src), binary));
        }
        let module_set: BTreeSet<Vec<String>> = entries
            .iter()
            .filter(|e| !e.3)
            .map(|e| e.2.clone())
            .collect();
        let files: Vec<FileInfo> = entries
            .into_iter()
            .map(|(rel, text, module, binary)| analyse(rel, text, module, binary, &module_set))
            .collect();
        let modules = files
            .iter()
            .enumerate()
            .filter(|(_, f)| !f.binary)
            .map(|(k, f)| (f.module.clone(), k))
            .collect();
        Tree { files, modules }
    }

    /// Reads every `.rs` file under `src/`.
    fn read(src: &Path) -> Tree {
        fn walk(dir: &Path, root: &Path, out: &mut Vec<(String, String)>) {
            let mut entries: Vec<_> = std::fs::read_dir(dir)
                .expect("read src/")
                .map(|e| e.unwrap().path())
                .collect();
            entries.sort();
            for p in entries {
                if p.is_dir() {
                    walk(&p, root, out);
                } else if p.extension().is_some_and(|e| e == "rs") {
                    let rel = p
                        .strip_prefix(root)
                        .unwrap()
                        .to_string_lossy()
                        .replace('\\', "/");
                    out.push((
                        rel,
                        std::fs::read_to_string(&p).expect("read a source file"),
                    ));
                }
            }
        }
        let root = src.parent().unwrap();
        let mut sources = Vec::new();
        walk(src, root, &mut sources);
        Tree::from_sources(&sources)
    }

    /// The file an absolute path lands in: the deepest module file that exists, following
    /// the re-exports (`pub use child::{A, B}`, `pub use child::*`) of the modules on the way.
    fn resolve(&self, path: &[String]) -> usize {
        self.resolve_at(path, 0)
    }

    fn resolve_at(&self, path: &[String], hops: usize) -> usize {
        let mut cur: Vec<String> = Vec::new();
        for (k, seg) in path.iter().enumerate() {
            let mut next = cur.clone();
            next.push(seg.clone());
            if self.modules.contains_key(&next) {
                cur = next;
                continue;
            }
            // `seg` is an item of module `cur`: follow a re-export to where it is defined.
            let file = &self.files[self.modules[&cur]];
            if hops < 16 {
                if let Some(target) = file.reexports.get(seg) {
                    let p: Vec<String> = target.iter().chain(&path[k + 1..]).cloned().collect();
                    return self.resolve_at(&p, hops + 1);
                }
                for glob in &file.glob_reexports {
                    if self.exposes(glob, seg, hops + 1) {
                        let p: Vec<String> = glob.iter().chain(&path[k..]).cloned().collect();
                        return self.resolve_at(&p, hops + 1);
                    }
                }
            }
            return self.modules[&cur];
        }
        self.modules[&cur]
    }

    /// Whether module `module` makes `name` public (defines it, or re-exports it).
    fn exposes(&self, module: &[String], name: &str, hops: usize) -> bool {
        let Some(&k) = self.modules.get(module) else {
            return false;
        };
        let f = &self.files[k];
        let mut child = module.to_vec();
        child.push(name.to_string());
        f.pub_items.contains(name)
            || f.reexports.contains_key(name)
            || self.modules.contains_key(&child)
            || (hops < 16
                && f.glob_reexports
                    .iter()
                    .any(|g| self.exposes(g, name, hops + 1)))
    }

    /// The room of a library file: its top-level module (`""` for `lib.rs`).
    fn room(&self, file: usize) -> &str {
        self.files[file].module.first().map_or("", String::as_str)
    }

    /// The rooms a reference touches: the room of the file it resolves to, and the room it
    /// names first (they differ when a module re-exports another room's item). `cli` when it
    /// names the CLI; `""` when it lands in `lib.rs` itself.
    fn rooms_of(&self, r: &Ref) -> BTreeSet<String> {
        let mut rooms = BTreeSet::new();
        if r.abs.first().map(String::as_str) == Some("cli") {
            rooms.insert("cli".to_string());
            return rooms;
        }
        rooms.insert(self.room(self.resolve(&r.abs)).to_string());
        if let Some(first) = r.abs.first() {
            if self.modules.contains_key(std::slice::from_ref(first)) {
                rooms.insert(first.clone());
            }
        }
        rooms
    }

    fn library(&self) -> impl Iterator<Item = (usize, &FileInfo)> {
        self.files.iter().enumerate().filter(|(_, f)| !f.binary)
    }

    /// Every reference from a file of a room in `from` to a room other than its own for
    /// which `allowed(room)` is false, as `file:line: `path` — why`.
    fn room_violations(
        &self,
        from: &[&str],
        allowed: impl Fn(&str) -> bool,
        why: impl Fn(&str, &str) -> String,
    ) -> Vec<String> {
        let mut out = Vec::new();
        for (k, f) in self.library() {
            let own = self.room(k);
            if !from.contains(&own) {
                continue;
            }
            for r in &f.refs {
                for room in self.rooms_of(r) {
                    if room != own && !allowed(&room) {
                        out.push(format!(
                            "{}:{}: `{}` — {}",
                            f.rel,
                            r.line,
                            r.text,
                            why(own, &room)
                        ));
                    }
                }
            }
        }
        out
    }

    /// File → file edges of the library: (from, to, line, path). Self-references are dropped,
    /// and so is test code: a `#[cfg(test)]` item may use helpers that use the code under
    /// test (a solver's tests building a packing), which is no cycle of the library itself.
    fn edges(&self) -> Vec<(usize, usize, usize, String)> {
        let mut edges = Vec::new();
        for (k, f) in self.library() {
            for r in f.refs.iter().filter(|r| !r.in_test) {
                if r.abs.first().map(String::as_str) == Some("cli") {
                    continue;
                }
                let to = self.resolve(&r.abs);
                if to != k {
                    edges.push((k, to, r.line, r.text.clone()));
                }
            }
        }
        edges
    }

    /// Every import cycle: each strongly connected component of more than one file, as a
    /// message listing its files, one cycle through them and every edge inside it.
    fn cycles(&self) -> Vec<String> {
        let edges = self.edges();
        let n = self.files.len();
        let mut adj: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
        for (a, b, _, _) in &edges {
            adj[*a].insert(*b);
        }
        let mut out = Vec::new();
        for comp in scc(&adj) {
            if comp.len() < 2 {
                continue;
            }
            let inside: BTreeSet<usize> = comp.iter().copied().collect();
            let names: Vec<&str> = comp.iter().map(|&k| self.files[k].rel.as_str()).collect();
            let cycle = shortest_cycle(&adj, comp[0], &inside);
            let cycle: Vec<&str> = cycle.iter().map(|&k| self.files[k].rel.as_str()).collect();
            let mut msg = format!(
                "import cycle between {} files: {}\n    e.g. {}\n    edges:",
                comp.len(),
                names.join(", "),
                cycle.join(" → ")
            );
            for (a, b, line, text) in &edges {
                if inside.contains(a) && inside.contains(b) {
                    msg.push_str(&format!(
                        "\n      {}:{}: `{}` → {}",
                        self.files[*a].rel, line, text, self.files[*b].rel
                    ));
                }
            }
            out.push(msg);
        }
        out
    }
}

/// Strongly connected components (Tarjan), each sorted.
fn scc(adj: &[BTreeSet<usize>]) -> Vec<Vec<usize>> {
    struct State<'a> {
        adj: &'a [BTreeSet<usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on_stack: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(s: &mut State, v: usize) {
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on_stack[v] = true;
        for &w in s.adj[v].iter() {
            match s.index[w] {
                None => {
                    visit(s, w);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(iw) if s.on_stack[w] => s.low[v] = s.low[v].min(iw),
                _ => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack[w] = false;
                comp.push(w);
                if w == v {
                    break;
                }
            }
            comp.sort();
            s.out.push(comp);
        }
    }
    let n = adj.len();
    let mut s = State {
        adj,
        index: vec![None; n],
        low: vec![0; n],
        on_stack: vec![false; n],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.out
}

/// A shortest cycle from `start` back to itself within `inside` (breadth first), as the list
/// of files with `start` at both ends.
fn shortest_cycle(adj: &[BTreeSet<usize>], start: usize, inside: &BTreeSet<usize>) -> Vec<usize> {
    let mut prev: BTreeMap<usize, usize> = BTreeMap::new();
    let mut queue = VecDeque::from([start]);
    while let Some(v) = queue.pop_front() {
        for &w in &adj[v] {
            if !inside.contains(&w) {
                continue;
            }
            if w == start {
                let mut path = vec![start, v];
                let mut u = v;
                while u != start {
                    u = prev[&u];
                    path.push(u);
                }
                path.reverse();
                return path;
            }
            if let std::collections::btree_map::Entry::Vacant(e) = prev.entry(w) {
                e.insert(v);
                queue.push_back(w);
            }
        }
    }
    vec![start]
}

/// The tree under `src/`, read once for all tests.
fn tree() -> &'static Tree {
    static TREE: OnceLock<Tree> = OnceLock::new();
    TREE.get_or_init(|| Tree::read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src")))
}

fn assert_none(rule: &str, violations: Vec<String>) {
    assert!(
        violations.is_empty(),
        "{rule} (docs/architecture.md) is broken {} time(s):\n  {}\n",
        violations.len(),
        violations.join("\n  ")
    );
}

// ---------------------------------------------------------------------------------------------
// The rules.
// ---------------------------------------------------------------------------------------------

/// Not a rule of the page but what the rules stand on: every top-level module of the library
/// is one of the rooms above, and every reference lands in one.
#[test]
fn every_module_and_reference_is_in_a_known_room() {
    let t = tree();
    let mut bad = Vec::new();
    for (k, f) in t.library() {
        let room = t.room(k);
        if !room.is_empty() && !LIBRARY.contains(&room) {
            bad.push(format!(
                "{}: room `{room}` is not in the list of rooms of tests/suite/architecture.rs \
                 (add it to BASE, SOLVERS or LIBRARY, and to docs/architecture.md)",
                f.rel
            ));
        }
        for r in &f.refs {
            for room in t.rooms_of(r) {
                if room.is_empty() {
                    bad.push(format!(
                        "{}:{}: `{}` — names an item of the crate root that is not \
                         `crate::Error`/`crate::Result`",
                        f.rel, r.line, r.text
                    ));
                }
            }
        }
    }
    assert_none("the list of rooms", bad);
}

#[test]
fn rule_1_base_helpers_use_only_base_helpers() {
    let v = tree().room_violations(
        BASE,
        |r| BASE.contains(&r),
        |from, to| format!("a base helper ({from}) may use only base helpers, not {to} (rule 1)"),
    );
    assert_none("rule 1", v);
}

#[test]
fn rule_2_solvers_use_only_base_helpers() {
    let v = tree().room_violations(
        SOLVERS,
        |r| BASE.contains(&r),
        |from, to| {
            if SOLVERS.contains(&to) {
                format!("a solver ({from}) may not use another solver ({to}) (rule 2)")
            } else {
                format!("a solver ({from}) may use only base helpers, not {to} (rule 2)")
            }
        },
    );
    assert_none("rule 2", v);
}

#[test]
fn rule_3_coupling_uses_only_base_helpers_and_solvers() {
    let v = tree().room_violations(
        &["coupling"],
        |r| BASE.contains(&r) || SOLVERS.contains(&r),
        |_, to| format!("coupling may use only base helpers and the solvers, not {to} (rule 3)"),
    );
    assert_none("rule 3", v);
}

#[test]
fn rule_4_io_uses_only_base_helpers() {
    let v = tree().room_violations(
        &["io"],
        |r| BASE.contains(&r),
        |_, to| format!("the output writers (io) may use only base helpers, not {to} (rule 4)"),
    );
    assert_none("rule 4", v);
}

#[test]
fn rule_5_scenario_does_not_use_sweep() {
    let v = tree().room_violations(
        &["scenario"],
        |r| LIBRARY.contains(&r) && r != "sweep",
        |_, to| format!("scenario may use the library but sweep, not {to} (rule 5)"),
    );
    assert_none("rule 5", v);
}

#[test]
fn rule_6_sweep_uses_only_the_library() {
    let v = tree().room_violations(
        &["sweep"],
        |r| LIBRARY.contains(&r),
        |_, to| format!("sweep may use the library only, not {to} (rule 6)"),
    );
    assert_none("rule 6", v);
}

#[test]
fn rule_7_library_never_sees_the_cli() {
    let t = tree();
    let mut v = Vec::new();
    for (_, f) in t.library() {
        for r in &f.refs {
            if t.rooms_of(r).contains("cli") {
                v.push(format!(
                    "{}:{}: `{}` — the library may not use the CLI (rule 7)",
                    f.rel, r.line, r.text
                ));
            }
        }
        for line in &f.mod_cli {
            v.push(format!(
                "{}:{line}: `mod cli` — only src/main.rs declares the CLI (rule 7)",
                f.rel
            ));
        }
    }
    assert_none("rule 7", v);
}

#[test]
fn rule_8_no_import_cycles() {
    assert_none(
        "rule 8 (no import cycle between files of the library)",
        tree().cycles(),
    );
}

#[test]
fn rule_9_long_files_say_why() {
    let v: Vec<String> = tree()
        .files
        .iter()
        .filter(|f| f.lines > MAX_LINES && !f.says_length)
        .map(|f| {
            format!(
                "{}: {} lines — over {MAX_LINES} without a `//! Length:` line in its head \
                 comment (rule 9)",
                f.rel, f.lines
            )
        })
        .collect();
    assert_none("rule 9", v);
}

// ---------------------------------------------------------------------------------------------
// Self-tests of the parser, the resolver and the cycle detector on a tiny in-memory crate.
// ---------------------------------------------------------------------------------------------

/// A tiny crate: `== path` lines start each file.
const TOY: &str = r#"
== src/lib.rs
pub mod a;
pub mod b;
pub mod error;
pub use error::{Error, Result};
== src/error.rs
pub struct Error;
pub type Result<T> = std::result::Result<T, Error>;
== src/a/mod.rs
//! Uses [`crate::b::helper`] in a doc link only.
pub mod inner;
pub mod spec;
pub use inner::Thing;
pub use spec::*;
== src/a/inner.rs
use crate::b::helper;
use crate::{Error, Result};
pub struct Thing;
== src/a/spec.rs
pub const fn knob() -> u8 { 1 }
fn f() -> &'static str { "crate::b::nope" }
== src/b.rs
use crate::a::{Thing, knob as k};
// crate::a::spec::x
pub fn helper() {
    let c = '"';
    super::a::inner::Thing;
}
#[cfg(test)]
mod tests {
    use super::*;
    use crate::a::spec::knob;
}
== src/main.rs
mod cli;
fn main() { crate::cli::run(); }
== src/cli/mod.rs
pub fn run() {}
"#;

fn toy() -> Tree {
    let files: Vec<(String, String)> = TOY
        .split("\n== ")
        .skip(1)
        .map(|f| {
            let (path, text) = f.split_once('\n').unwrap();
            (path.to_string(), text.to_string())
        })
        .collect();
    Tree::from_sources(&files)
}

fn file_of(t: &Tree, rel: &str) -> usize {
    t.files.iter().position(|f| f.rel == rel).unwrap()
}

#[test]
fn self_test_strip_and_use_groups() {
    let src = r##"use crate::lbm::{d2q9::{CX, CY}, Lattice, self};
// crate::x
let s = r#"crate::y"#; /* crate::z /* nested */ */ let l: &'a str = "a\"crate::w";
"##;
    let t = tokenize(&strip(src));
    let mut i = 1;
    let mut leaves = Vec::new();
    parse_use_tree(&t, &mut i, &[], &mut leaves);
    let paths: Vec<String> = leaves.iter().map(|l| l.segs.join("::")).collect();
    assert_eq!(
        paths,
        [
            "crate::lbm::d2q9::CX",
            "crate::lbm::d2q9::CY",
            "crate::lbm::Lattice",
            "crate::lbm"
        ]
    );
    let words: Vec<&str> = t.iter().map(|t| t.text.as_str()).collect();
    for gone in ["x", "y", "z", "w", "nested"] {
        assert!(
            !words.contains(&gone),
            "`{gone}` should be stripped: {words:?}"
        );
    }
    assert_eq!(t.last().unwrap().line, 3);
}

#[test]
fn self_test_resolver_and_cycle_detector() {
    let t = toy();
    let (lib, a, inner, spec, b, error) = (
        file_of(&t, "src/lib.rs"),
        file_of(&t, "src/a/mod.rs"),
        file_of(&t, "src/a/inner.rs"),
        file_of(&t, "src/a/spec.rs"),
        file_of(&t, "src/b.rs"),
        file_of(&t, "src/error.rs"),
    );
    let path = |s: &str| s.split("::").map(str::to_string).collect::<Vec<_>>();
    assert_eq!(t.resolve(&path("a::Thing")), inner, "named re-export");
    assert_eq!(t.resolve(&path("a::knob")), spec, "glob re-export");
    assert_eq!(t.resolve(&path("a::nothing")), a);
    assert_eq!(
        t.resolve(&path("Error")),
        error,
        "crate::Error belongs to error"
    );
    assert_eq!(t.resolve(&[]), lib);
    // Comments, doc links and strings give no references; the test module's do, marked.
    assert!(t.files[a].refs.is_empty());
    assert!(t.files[spec].refs.is_empty());
    let refs: Vec<(&str, bool)> = t.files[b]
        .refs
        .iter()
        .map(|r| (r.text.as_str(), r.in_test))
        .collect();
    assert_eq!(
        refs,
        [
            ("crate::a::Thing", false),
            ("crate::a::knob", false),
            ("super::a::inner::Thing", false),
            ("super::*", true),
            ("crate::a::spec::knob", true),
        ]
    );
    // The binary's `mod cli` and `crate::cli` stay out of the library.
    assert!(t.library().all(|(_, f)| f.mod_cli.is_empty()));
    // b → a/inner.rs (through the re-export) → b: one cycle; b → spec.rs is outside it.
    let cycles = t.cycles();
    assert_eq!(cycles.len(), 1, "{cycles:?}");
    assert!(
        cycles[0].contains("src/a/inner.rs, src/b.rs"),
        "{}",
        cycles[0]
    );
    assert!(
        cycles[0].contains("src/a/inner.rs:1: `crate::b::helper` → src/b.rs"),
        "{}",
        cycles[0]
    );
    assert!(!cycles[0].contains("spec.rs"), "{}", cycles[0]);
    // The room rules on the toy: `b` may not use `a`.
    let v = t.room_violations(&["b"], |r| r == "error", |f, to| format!("{f} → {to}"));
    assert_eq!(v.len(), 4, "{v:?}");
    assert_eq!(v[0], "src/b.rs:1: `crate::a::Thing` — b → a");
}
