//! Clean-ups of rust-hdl's generated Verilog text: readable names and one module per distinct
//! body.
//!
//! rust-hdl's `generate_verilog` names the top module `top`, writes one module per *instance*
//! (`top$in_a`, `top$rem$3`, ...) and uses `$` inside hierarchical names. [`rename_rust_hdl_names`]
//! gives the top a real name and turns `$` into `__`; [`merge_identical_modules`] then keeps one
//! copy of modules whose text differs only in their name (e.g. the 25-bit pipeline registers of
//! a divider), which shrinks files and simulator build times without changing behaviour.

/// The identifiers of `verilog`, each with its byte offset: maximal runs of `[A-Za-z0-9_$]`
/// starting with a letter or `_` (so `$signed` and the digits of sized literals such as
/// `8'hff` are left out).
pub fn identifiers(verilog: &str) -> impl Iterator<Item = (usize, &str)> {
    let bytes = verilog.as_bytes();
    let is_ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_' || c == b'$';
    let mut i = 0;
    std::iter::from_fn(move || {
        while i < bytes.len() {
            let c = bytes[i];
            let starts_ident = (c.is_ascii_alphabetic() || c == b'_')
                && (i == 0 || !(is_ident(bytes[i - 1]) || bytes[i - 1] == b'\''));
            if !starts_ident {
                i += 1;
                continue;
            }
            let start = i;
            while i < bytes.len() && is_ident(bytes[i]) {
                i += 1;
            }
            return Some((start, &verilog[start..i]));
        }
        None
    })
}

/// Rewrites every identifier of `verilog` (see [`identifiers`]) for which `f` returns a
/// replacement.
pub fn map_identifiers(verilog: &str, f: impl Fn(&str) -> Option<String>) -> String {
    let mut out = String::with_capacity(verilog.len() + verilog.len() / 8);
    let mut copied = 0;
    for (start, word) in identifiers(verilog) {
        if let Some(new) = f(word) {
            out.push_str(&verilog[copied..start]);
            out.push_str(&new);
            copied = start + word.len();
        }
    }
    out.push_str(&verilog[copied..]);
    out
}

/// Renames rust-hdl's module `top` to `core_name`, its sub-modules `top$x$y` to
/// `core_name__x__y`, and every `$` inside an identifier to `__` (system functions such as
/// `$signed` keep theirs). rust-hdl field names used here never contain `__`, so no two names
/// collide.
pub fn rename_rust_hdl_names(verilog: &str, core_name: &str) -> String {
    map_identifiers(verilog, |word| {
        if word == "top" {
            Some(core_name.to_string())
        } else if let Some(rest) = word.strip_prefix("top$") {
            Some(format!("{core_name}__{}", rest.replace('$', "__")))
        } else if word.contains('$') {
            Some(word.replace('$', "__"))
        } else {
            None
        }
    })
}

enum Segment {
    Text(String),
    Module { name: String, text: String },
}

/// Splits Verilog text into modules (`module NAME...` up to the `endmodule` line, both at the
/// start of a line) and the text between them.
fn split_modules(verilog: &str) -> Vec<Segment> {
    let mut segments = Vec::new();
    let mut text = String::new();
    let mut module: Option<(String, String)> = None;
    for line in verilog.split_inclusive('\n') {
        match &mut module {
            None => {
                if let Some(rest) = line.strip_prefix("module ") {
                    let name: String = rest
                        .chars()
                        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == '$')
                        .collect();
                    if !text.is_empty() {
                        segments.push(Segment::Text(std::mem::take(&mut text)));
                    }
                    module = Some((name, line.to_string()));
                } else {
                    text.push_str(line);
                }
            }
            Some((_, body)) => {
                body.push_str(line);
                if line.starts_with("endmodule") {
                    let (name, text) = module.take().unwrap();
                    segments.push(Segment::Module { name, text });
                }
            }
        }
    }
    if let Some((name, body)) = module {
        segments.push(Segment::Module { name, text: body });
    }
    if !text.is_empty() {
        segments.push(Segment::Text(text));
    }
    segments
}

/// Keeps one module out of each group whose text is identical once its own name is blanked
/// out (the first one keeps its name; instantiations of the others are renamed to it), and
/// repeats until nothing changes, since merging children can make parents identical.
pub fn merge_identical_modules(verilog: &str) -> String {
    use std::collections::HashMap;
    let mut segments = split_modules(verilog);
    loop {
        let mut canonical_of_body: HashMap<String, String> = HashMap::new();
        let mut alias: HashMap<String, String> = HashMap::new();
        for seg in &segments {
            if let Segment::Module { name, text } = seg {
                let body = map_identifiers(text, |w| (w == name).then(|| "@".to_string()));
                match canonical_of_body.get(&body) {
                    Some(first) => {
                        alias.insert(name.clone(), first.clone());
                    }
                    None => {
                        canonical_of_body.insert(body, name.clone());
                    }
                }
            }
        }
        if alias.is_empty() {
            break;
        }
        segments = segments
            .into_iter()
            .filter(|seg| !matches!(seg, Segment::Module { name, .. } if alias.contains_key(name)))
            .map(|seg| {
                let rename = |t: &str| map_identifiers(t, |w| alias.get(w).cloned());
                match seg {
                    Segment::Text(t) => Segment::Text(rename(&t)),
                    Segment::Module { name, text } => Segment::Module {
                        name,
                        text: rename(&text),
                    },
                }
            })
            .collect();
    }
    segments
        .into_iter()
        .map(|seg| match seg {
            Segment::Text(t) => t,
            Segment::Module { text, .. } => text,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renaming_keeps_system_functions_and_maps_hierarchy() {
        let v = "module top(a);\ntop$in_a in_a(.d(in_a$d));\nx = $signed(y$q) + 8'hff;\n";
        let r = rename_rust_hdl_names(v, "fp_x_core");
        assert_eq!(
            r,
            "module fp_x_core(a);\nfp_x_core__in_a in_a(.d(in_a__d));\nx = $signed(y__q) + 8'hff;\n"
        );
    }

    #[test]
    fn identical_modules_merge_and_distinct_ones_stay() {
        let v = "\
module t(x);
r_a a(.d(x));
r_b b(.d(x));
r_c c(.d(x));
endmodule // t

module r_a(d);
reg [3:0] q; // r_a
endmodule // r_a

module r_b(d);
reg [3:0] q; // r_b
endmodule // r_b

module r_c(d);
reg [4:0] q;
endmodule // r_c
";
        let merged = merge_identical_modules(v);
        assert!(
            merged.contains("r_a a(.d(x));\nr_a b(.d(x));\nr_c c(.d(x));"),
            "{merged}"
        );
        assert!(!merged.contains("module r_b"), "{merged}");
        assert!(merged.contains("module r_a(d)") && merged.contains("module r_c(d)"));
    }
}
