//! Radiance primitives as text: a tokenizer that keeps line numbers, a
//! parser, a printer, and the mapping to brtf-model materials.

use brtf_model::{Material, MaterialKind};
use glam::DVec3;
use std::fmt;

/// Every primitive type Radiance 6 knows, so misspellings are caught.
const RADIANCE_TYPES: &[&str] = &[
    "source",
    "sphere",
    "bubble",
    "polygon",
    "cone",
    "cup",
    "cylinder",
    "tube",
    "ring",
    "instance",
    "mesh",
    "light",
    "illum",
    "glow",
    "spotlight",
    "mirror",
    "mist",
    "prism1",
    "prism2",
    "metal",
    "metal2",
    "plastic",
    "plastic2",
    "trans",
    "trans2",
    "dielectric",
    "interface",
    "glass",
    "plasfunc",
    "metfunc",
    "transfunc",
    "BRTDfunc",
    "plasdata",
    "metdata",
    "transdata",
    "BSDF",
    "aBSDF",
    "ashik2",
    "WGMDfunc",
    "antimatter",
    "texfunc",
    "texdata",
    "colorfunc",
    "brightfunc",
    "colordata",
    "brightdata",
    "colorpict",
    "colortext",
    "brighttext",
    "mixfunc",
    "mixdata",
    "mixpict",
    "mixtext",
    "alias",
    "spectrum",
    "specfile",
    "specfunc",
    "specdata",
    "specpict",
];

/// A parse or conversion error, located in a file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RadError {
    /// The file (or a label such as `<stdin>`).
    pub path: String,
    /// 1-based line number.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for RadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: {}", self.path, self.line, self.message)
    }
}

impl std::error::Error for RadError {}

/// One Radiance primitive.
#[derive(Debug, Clone, PartialEq)]
pub struct Primitive {
    /// The modifier (`void` for a plain material).
    pub modifier: String,
    /// The type (`metal`, `polygon`, ...).
    pub kind: String,
    /// The identifier.
    pub name: String,
    /// String arguments.
    pub strings: Vec<String>,
    /// Integer arguments, kept as written.
    pub ints: Vec<String>,
    /// Real arguments.
    pub reals: Vec<f64>,
    /// Line where the primitive starts (0 when built in memory).
    pub line: usize,
}

struct Token<'a> {
    text: &'a str,
    line: usize,
}

fn tokenize<'a>(text: &'a str, path: &str) -> Result<Vec<Token<'a>>, RadError> {
    let mut tokens = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let content = raw.split('#').next().unwrap_or("");
        if content.trim_start().starts_with('!') {
            return Err(RadError {
                path: path.to_string(),
                line,
                message:
                    "inline commands (`!...`) are not supported; run them first and save the output"
                        .into(),
            });
        }
        tokens.extend(content.split_whitespace().map(|t| Token { text: t, line }));
    }
    Ok(tokens)
}

/// Walks the token list, producing located errors.
struct Cursor<'t, 'a> {
    tokens: &'t [Token<'a>],
    pos: usize,
    path: &'t str,
}

impl<'t, 'a> Cursor<'t, 'a> {
    fn error(&self, line: usize, message: String) -> RadError {
        RadError {
            path: self.path.to_string(),
            line,
            message,
        }
    }

    fn last_line(&self) -> usize {
        self.tokens.last().map_or(1, |t| t.line)
    }

    fn next(&mut self, what: &str, context: &str) -> Result<&'t Token<'a>, RadError> {
        let token = self.tokens.get(self.pos).ok_or_else(|| {
            self.error(
                self.last_line(),
                format!("file ends {context}: expected {what}"),
            )
        })?;
        self.pos += 1;
        Ok(token)
    }

    /// An argument list: its count, then that many tokens.
    fn list(&mut self, name: &str, what: &str) -> Result<&'t [Token<'a>], RadError> {
        let context = format!("inside `{name}`");
        let t = self.next(&format!("the number of {what} arguments"), &context)?;
        let n = t.text.parse::<usize>().map_err(|_| {
            self.error(
                t.line,
                format!(
                    "`{name}`: expected the number of {what} arguments, found `{}`",
                    t.text
                ),
            )
        })?;
        let available = self.tokens.len() - self.pos;
        if n > available {
            return Err(self.error(
                self.last_line(),
                format!(
                    "`{name}` declares {n} {what} arguments but the file ends after {available}"
                ),
            ));
        }
        let slice = &self.tokens[self.pos..self.pos + n];
        self.pos += n;
        Ok(slice)
    }
}

/// Parses every primitive in `text`. `path` is used in error messages.
pub fn parse_primitives(text: &str, path: &str) -> Result<Vec<Primitive>, RadError> {
    let tokens = tokenize(text, path)?;
    let mut cursor = Cursor {
        tokens: &tokens,
        pos: 0,
        path,
    };
    let mut primitives = Vec::new();
    while cursor.pos < tokens.len() {
        let start = tokens[cursor.pos].line;
        let context = format!("inside the primitive starting on line {start}");
        let modifier = cursor.next("a modifier", &context)?.text.to_string();
        let kind_token = cursor.next("a primitive type", &context)?;
        let kind = kind_token.text.to_string();
        if !RADIANCE_TYPES.contains(&kind.as_str()) {
            return Err(cursor.error(kind_token.line, format!("unknown primitive type `{kind}`")));
        }
        let name = cursor.next("an identifier", &context)?.text.to_string();
        if kind == "alias" {
            // `modifier alias name reference`: no argument lists.
            let reference = cursor.next("the aliased identifier", &context)?;
            primitives.push(Primitive {
                modifier,
                kind,
                name,
                strings: vec![reference.text.to_string()],
                ints: Vec::new(),
                reals: Vec::new(),
                line: start,
            });
            continue;
        }
        let strings = cursor
            .list(&name, "string")?
            .iter()
            .map(|t| t.text.to_string())
            .collect();
        let ints = cursor
            .list(&name, "integer")?
            .iter()
            .map(|t| t.text.to_string())
            .collect();
        let reals = cursor
            .list(&name, "real")?
            .iter()
            .map(|t| {
                t.text
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| {
                        cursor.error(
                            t.line,
                            format!("`{name}`: real argument `{}` is not a number", t.text),
                        )
                    })
            })
            .collect::<Result<Vec<f64>, RadError>>()?;
        primitives.push(Primitive {
            modifier,
            kind,
            name,
            strings,
            ints,
            reals,
            line: start,
        });
    }
    Ok(primitives)
}

/// Converts a Ward-type primitive to a material, checking its arguments.
pub fn material_from_primitive(p: &Primitive, path: &str) -> Result<Material, RadError> {
    let err = |message: String| RadError {
        path: path.to_string(),
        line: p.line,
        message,
    };
    let kind: MaterialKind = p.kind.parse().map_err(|_| {
        err(format!(
            "`{}` is a {}, not one of plastic, metal, trans, plastic2, metal2, trans2",
            p.name, p.kind
        ))
    })?;
    if !p.ints.is_empty() {
        return Err(err(format!(
            "{} `{}` takes 0 integer arguments, found {}",
            kind,
            p.name,
            p.ints.len()
        )));
    }
    let orientation = if kind.is_anisotropic() {
        if p.strings.len() != 4 {
            return Err(err(format!(
                "{kind} `{}` takes 4 string arguments (ux uy uz funcfile), found {}",
                p.name,
                p.strings.len()
            )));
        }
        let mut xyz = [0.0; 3];
        for (i, s) in p.strings[..3].iter().enumerate() {
            xyz[i] = s.parse::<f64>().map_err(|_| {
                err(format!(
                    "{kind} `{}`: orientation component `{s}` must be a numeric constant here",
                    p.name
                ))
            })?;
        }
        Some(DVec3::from_array(xyz))
    } else {
        if !p.strings.is_empty() {
            return Err(err(format!(
                "{kind} `{}` takes 0 string arguments, found {}",
                p.name,
                p.strings.len()
            )));
        }
        None
    };
    if p.reals.len() != kind.n_args() {
        return Err(err(format!(
            "{kind} `{}` takes {} real arguments, found {}",
            p.name,
            kind.n_args(),
            p.reals.len()
        )));
    }
    brtf_model::check_args(kind, &p.reals).map_err(|e| err(format!("{kind} `{}`: {e}", p.name)))?;
    Material::new(kind, &p.reals, orientation).map_err(|e| err(format!("{kind} `{}`: {e}", p.name)))
}

/// Picks the material called `name`, or the file's one top material, as
/// [`crate::select_composite`] does, when it is one primitive (not a mixture).
pub fn select_material(
    primitives: &[Primitive],
    name: Option<&str>,
    path: &str,
) -> Result<(String, Material), RadError> {
    let (name, composite) = crate::select_composite(primitives, name, path)?;
    match composite.single() {
        Some(m) => Ok((name, *m)),
        None => Err(RadError {
            path: path.to_string(),
            line: primitives
                .iter()
                .rfind(|p| p.name == name)
                .map_or(1, |p| p.line),
            message: format!(
                "`{name}` is a mixture of {} primitives; one primitive is needed here",
                composite.components().len()
            ),
        }),
    }
}

/// `text` made a Radiance identifier that is also a safe file stem: ASCII
/// letters, digits, `_`, `-` and `.`, others replaced by `_`, not starting
/// with `-` or `.`, without trailing `_`. `None` when nothing is left.
pub fn identifier(text: &str) -> Option<String> {
    let ok = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.');
    let mapped: String = text.chars().map(|c| if ok(c) { c } else { '_' }).collect();
    let trimmed = mapped
        .trim_start_matches(['-', '.', '_'])
        .trim_end_matches(['_', '-', '.']);
    (!trimmed.is_empty()).then(|| trimmed.to_string())
}

/// The primitive `void <type> <name>` for a material.
pub fn primitive_from_material(material: &Material, name: &str) -> Primitive {
    let strings = if material.kind().is_anisotropic() {
        let o = material.orientation();
        vec![fmt_real(o.x), fmt_real(o.y), fmt_real(o.z), ".".to_string()]
    } else {
        Vec::new()
    };
    Primitive {
        modifier: "void".into(),
        kind: material.kind().name().into(),
        name: name.into(),
        strings,
        ints: Vec::new(),
        reals: material.args().to_vec(),
        line: 0,
    }
}

/// Shortest text that reads back as the same f64.
pub(crate) fn fmt_real(x: f64) -> String {
    let s = format!("{x}");
    if s == "-0" { "0".into() } else { s }
}

/// Radiance text for a primitive, one argument list per line.
pub fn format_primitive(p: &Primitive) -> String {
    // `modifier alias name reference` has no argument lists.
    if p.kind == "alias" {
        let reference = p.strings.first().map_or("", String::as_str);
        return format!("{} alias {} {reference}\n", p.modifier, p.name);
    }
    let mut out = format!("{} {} {}\n", p.modifier, p.kind, p.name);
    out += &p.strings.len().to_string();
    for s in &p.strings {
        out += " ";
        out += s;
    }
    out += "\n";
    out += &p.ints.len().to_string();
    for s in &p.ints {
        out += " ";
        out += s;
    }
    out += "\n";
    out += &p.reals.len().to_string();
    for r in &p.reals {
        out += " ";
        out += &fmt_real(*r);
    }
    out += "\n";
    out
}
