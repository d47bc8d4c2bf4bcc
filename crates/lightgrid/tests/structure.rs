//! House rules read from the sources:
//! - function length: no function outside tests is longer than `MAX_LINES` lines (from its
//!   `fn` line to its closing brace), in any crate of the workspace, examples included. A
//!   long function is split where it reads as steps;
//! - one way to compose shaders: the library's WGSL is put together only by `shader`'s keys
//!   and defs, never by `concat!` of files or `.replace` of placeholders in its text.

use std::path::{Path, PathBuf};

const MAX_LINES: usize = 100;

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    source_files(dir, "rs", out);
}

/// The files under `dir` whose extension is `ext`. Tests and their helpers are not held to
/// the rules; build outputs are not sources.
fn source_files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let p = entry.path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if p.is_dir() {
            if name != "tests" && name != "target" && !name.starts_with('.') {
                source_files(&p, ext, out);
            }
        } else if p.extension().is_some_and(|e| e == ext) {
            out.push(p);
        }
    }
}

/// The functions of `text` longer than `MAX_LINES` lines: (first line, name, lines). A
/// file's `#[cfg(test)] mod` and everything after it are skipped.
fn long_functions(text: &str) -> Vec<(usize, String, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let end = lines
        .windows(2)
        .position(|w| w[0].trim() == "#[cfg(test)]" && w[1].trim_start().starts_with("mod "))
        .unwrap_or(lines.len());
    let mut out = Vec::new();
    let mut i = 0;
    while i < end {
        let words: Vec<&str> = lines[i].split_whitespace().collect();
        let at = words.iter().position(|w| *w == "fn");
        let is_item = at.is_some_and(|k| {
            words[..k]
                .iter()
                .all(|w| w.starts_with("pub") || ["const", "async", "unsafe", "extern"].contains(w))
        });
        let Some(k) = at.filter(|_| is_item && words.len() > at.unwrap() + 1) else {
            i += 1;
            continue;
        };
        let name: String = words[k + 1]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let (mut depth, mut started, mut j) = (0i32, false, i);
        let mut string = false;
        while j < lines.len() {
            let mut chars = lines[j].chars().peekable();
            while let Some(c) = chars.next() {
                match (string, c) {
                    // Braces in strings, comments and char literals are no blocks.
                    (true, '\\') => {
                        chars.next();
                    }
                    (true, '"') => string = false,
                    (true, _) => {}
                    (false, '"') => string = true,
                    (false, '/') if chars.peek() == Some(&'/') => break,
                    (false, '\'') => {
                        let rest: String = chars.clone().take(2).collect();
                        if rest.ends_with('\'') {
                            chars.nth(1);
                        }
                    }
                    (false, '{') => {
                        depth += 1;
                        started = true;
                    }
                    (false, '}') => depth -= 1,
                    _ => {}
                }
            }
            if started && depth == 0 || !started && lines[j].trim_end().ends_with(';') {
                break;
            }
            j += 1;
        }
        if started && j + 1 - i > MAX_LINES {
            out.push((i + 1, name, j + 1 - i));
        }
        i = if started { j + 1 } else { i + 1 };
    }
    out
}

#[test]
fn no_function_outside_tests_is_over_the_limit() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    rust_files(&crates, &mut files);
    assert!(files.len() > 50, "the workspace's sources were not found");
    let mut long = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        for (line, name, n) in long_functions(&text) {
            long.push(format!("{}:{line} {name}: {n} lines", f.display()));
        }
    }
    assert!(
        long.is_empty(),
        "functions over {MAX_LINES} lines (split them where they read as steps):\n{}",
        long.join("\n")
    );
}

/// The measure itself: a function of 101 lines is caught, one of 100 is not, and a test
/// module's functions are not measured.
#[test]
fn the_measure_counts_a_function_from_its_fn_line_to_its_closing_brace() {
    let body = |n: usize| "    let x = 1;\n".repeat(n);
    let long = format!("pub(crate) fn long() {{\n{}}}\n", body(99));
    let short = format!("fn short() {{\n{}}}\n", body(98));
    assert_eq!(long_functions(&long), vec![(1, "long".to_string(), 101)]);
    assert!(long_functions(&short).is_empty());
    let tricky = format!(
        "fn tricky() {{\n    let a = \"struct X {{\";\n    let b = '}}'; // }}\n{}}}\n",
        body(96)
    );
    assert!(long_functions(&tricky).is_empty(), "{tricky}");
    let tricky_long = tricky.replace("fn tricky() {\n", "fn tricky() {\n    let c = 2;\n");
    assert_eq!(
        long_functions(&tricky_long),
        vec![(1, "tricky".to_string(), 101)]
    );
    let in_tests = format!("#[cfg(test)]\nmod tests {{\n{long}}}\n");
    assert!(long_functions(&in_tests).is_empty());
}

/// Shaders have one composition path (`shader::ShaderKey`, `Def`, `parts!`): no `concat!` and
/// no `.replace` in the library's sources (neither has another use there), and no WGSL file
/// carries a placeholder to be replaced (`*_VALUE`) or a `#` directive but `#if` / `#else` /
/// `#endif`.
#[test]
fn shaders_are_composed_one_way() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    source_files(&src, "wgsl", &mut files);
    assert!(files.len() > 50, "the library's sources were not found");
    let mut found = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let wgsl = f.extension().is_some_and(|e| e == "wgsl");
        for (i, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            let directive = line.trim_start();
            let bad = if wgsl {
                code.contains("_VALUE")
                    || (directive.starts_with('#')
                        && !["#if ", "#else", "#endif"]
                            .iter()
                            .any(|d| directive.starts_with(d)))
            } else {
                code.contains("concat!(") || code.contains(".replace(")
            };
            if bad {
                found.push(format!("{}:{}: {line}", f.display(), i + 1));
            }
        }
    }
    assert!(
        found.is_empty(),
        "compose shaders through shader::ShaderKey / Def / parts!:\n{}",
        found.join("\n")
    );
}
