//! Lobe sums as Radiance text: constant `mixfunc` trees of Ward-type
//! primitives, read into a [`Composite`] and written back.
//!
//! `void mixfunc NAME 4 FOREGROUND BACKGROUND COEF . 0 0` is
//! `COEF · foreground + (1 − COEF) · background`, and rtrace mixes
//! linearly, so a tree of them with constant coefficients is the sum of
//! its leaves with the products of the coefficients along each path as
//! weights. A lobe sum of N lobes is written as the nested tree
//! `mix(m1, mix(m2, … mN, s2), s1)` whose coefficients are its
//! stick-breaking splits.
//!
//! References follow Radiance: a name refers to the last primitive of
//! that name defined **before** the one that uses it (`lastmod`).

use crate::primitive::{
    Primitive, RadError, fmt_real, material_from_primitive, primitive_from_material,
};
use brtf_model::{Composite, Material, MaterialKind, ShapeArg, lobe_splits};

/// Most primitives one mixture may expand to (shared subtrees count once
/// per use), so a hostile file cannot make the reader blow up.
pub const MAX_MIXTURE_PARTS: usize = 64;

/// Where a name is resolved: which primitive uses it, for messages.
struct Resolver<'a> {
    primitives: &'a [Primitive],
    path: &'a str,
    parts: usize,
}

impl Resolver<'_> {
    fn error(&self, line: usize, message: String) -> RadError {
        RadError {
            path: self.path.to_string(),
            line,
            message,
        }
    }

    /// The last primitive named `name` before index `before`.
    fn before(&self, name: &str, before: usize) -> Option<usize> {
        self.primitives[..before]
            .iter()
            .rposition(|p| p.name == name)
    }

    /// The primitives a mixfunc or alias at `index` refers to, by name.
    fn references(&self, index: usize) -> Vec<&str> {
        let p = &self.primitives[index];
        match p.kind.as_str() {
            "mixfunc" => p.strings.iter().take(2).map(String::as_str).collect(),
            "alias" => p.strings.iter().take(1).map(String::as_str).collect(),
            _ => Vec::new(),
        }
    }

    /// A chain of references from the primitive at `from` back to the
    /// name `target`, ignoring the order of definition (names only).
    fn cycle_through(&self, from: usize, target: &str) -> Option<Vec<String>> {
        let mut seen = vec![false; self.primitives.len()];
        let mut stack = vec![(from, vec![self.primitives[from].name.clone()])];
        while let Some((index, chain)) = stack.pop() {
            if std::mem::replace(&mut seen[index], true) {
                continue;
            }
            for name in self.references(index) {
                let mut next = chain.clone();
                next.push(name.to_string());
                if name == target {
                    return Some(next);
                }
                for (j, p) in self.primitives.iter().enumerate() {
                    if p.name == name && !seen[j] {
                        stack.push((j, next.clone()));
                    }
                }
            }
        }
        None
    }

    /// The weighted primitives of the material at `index`.
    fn parts(&mut self, index: usize) -> Result<Vec<(f64, Material)>, RadError> {
        let p = &self.primitives[index];
        if p.kind.parse::<MaterialKind>().is_ok() {
            self.parts += 1;
            if self.parts > MAX_MIXTURE_PARTS {
                return Err(self.error(
                    p.line,
                    format!(
                        "`{}`: the mixture expands to more than {MAX_MIXTURE_PARTS} primitives",
                        p.name
                    ),
                ));
            }
            return Ok(vec![(1.0, material_from_primitive(p, self.path)?)]);
        }
        match p.kind.as_str() {
            "alias" => {
                let target = self.reference(index, &p.strings[0])?;
                self.parts(target)
            }
            "mixfunc" => self.mixture(index),
            other => Err(self.error(
                p.line,
                format!(
                    "`{}` is a {other}, not one of plastic, metal, trans, plastic2, metal2, \
                     trans2 or a mixfunc of them",
                    p.name
                ),
            )),
        }
    }

    /// The primitive that `name`, used by the primitive at `user`, refers to.
    fn reference(&self, user: usize, name: &str) -> Result<usize, RadError> {
        let p = &self.primitives[user];
        if name == "void" {
            return Err(self.error(
                p.line,
                format!(
                    "{} `{}`: `void` (no material) cannot be part of a mixture brtf reads; \
                     give plastic, metal, trans, plastic2, metal2 or trans2 primitives",
                    p.kind, p.name
                ),
            ));
        }
        if let Some(j) = self.before(name, user) {
            return Ok(j);
        }
        let later = self.primitives[user + 1..]
            .iter()
            .position(|q| q.name == name)
            .map(|k| user + 1 + k);
        let message = match later {
            Some(j) => match self.cycle_through(j, &p.name) {
                Some(chain) => format!(
                    "{} `{}`: its materials refer back to it ({}): a mixture cannot contain \
                     itself",
                    p.kind,
                    p.name,
                    std::iter::once(p.name.clone())
                        .chain(chain)
                        .collect::<Vec<_>>()
                        .join(" -> ")
                ),
                None => format!(
                    "{} `{}`: `{name}` is defined only after it (line {}); Radiance needs a \
                     material defined before its use",
                    p.kind, p.name, self.primitives[j].line
                ),
            },
            None => format!(
                "{} `{}`: no material `{name}` before it in the file",
                p.kind, p.name
            ),
        };
        Err(self.error(p.line, message))
    }

    /// A constant mixfunc: `4 foreground background coefficient . 0 0`.
    fn mixture(&mut self, index: usize) -> Result<Vec<(f64, Material)>, RadError> {
        let p = &self.primitives[index];
        let err = |message: String| self.error(p.line, format!("mixfunc `{}`: {message}", p.name));
        if p.strings.len() != 4 {
            return Err(err(format!(
                "takes 4 string arguments (foreground background coefficient .) in a constant \
                 mixture, found {}",
                p.strings.len()
            )));
        }
        if !p.ints.is_empty() || !p.reals.is_empty() {
            return Err(err(format!(
                "a constant mixture has 0 integer and 0 real arguments, found {} and {}",
                p.ints.len(),
                p.reals.len()
            )));
        }
        let text = &p.strings[2];
        let coefficient = text
            .parse::<f64>()
            .ok()
            .filter(|c| c.is_finite())
            .ok_or_else(|| {
                err(format!(
                    "the coefficient `{text}` is not a number: brtf reads only constant \
                     mixtures (a pattern or function of the ray cannot be a lobe weight)"
                ))
            })?;
        if !(0.0..=1.0).contains(&coefficient) {
            return Err(err(format!(
                "the coefficient {text} is outside [0, 1]: the weights of the mixture would \
                 not be fractions"
            )));
        }
        if p.strings[3] != "." {
            return Err(err(format!(
                "function file `{}`: a constant mixture loads none (`.`)",
                p.strings[3]
            )));
        }
        let foreground = self.reference(index, &p.strings[0])?;
        let background = self.reference(index, &p.strings[1])?;
        let mut parts: Vec<(f64, Material)> = self
            .parts(foreground)?
            .into_iter()
            .map(|(w, m)| (w * coefficient, m))
            .collect();
        parts.extend(
            self.parts(background)?
                .into_iter()
                .map(|(w, m)| (w * (1.0 - coefficient), m)),
        );
        Ok(parts)
    }
}

/// The material (one Ward-type primitive, or a constant `mixfunc` tree of
/// them, through aliases) of the primitive at `index`.
pub fn composite_from_primitives(
    primitives: &[Primitive],
    index: usize,
    path: &str,
) -> Result<Composite, RadError> {
    let mut resolver = Resolver {
        primitives,
        path,
        parts: 0,
    };
    let parts = resolver.parts(index)?;
    let p = &primitives[index];
    Composite::mixture(parts).map_err(|e| RadError {
        path: path.to_string(),
        line: p.line,
        message: format!("`{}`: the weights of the mixture: {e}", p.name),
    })
}

/// Picks the material called `name` (the last primitive of that name), or
/// the file's one top material: the Ward-type primitive or constant
/// `mixfunc` that no mixfunc uses. A lobe sum written by brtf has its
/// `mixfunc` named after the material last, so that is the one chosen.
pub fn select_composite(
    primitives: &[Primitive],
    name: Option<&str>,
    path: &str,
) -> Result<(String, Composite), RadError> {
    let index = match name {
        Some(name) => primitives
            .iter()
            .rposition(|p| p.name == name)
            .ok_or_else(|| RadError {
                path: path.to_string(),
                line: 1,
                message: format!("no primitive named `{name}` in the file"),
            })?,
        None => top_material(primitives, path)?,
    };
    let composite = composite_from_primitives(primitives, index, path)?;
    Ok((primitives[index].name.clone(), composite))
}

/// The one material of the file that no mixfunc or alias uses (an alias
/// of a material counts as one).
fn top_material(primitives: &[Primitive], path: &str) -> Result<usize, RadError> {
    let is_material = |p: &Primitive| p.kind == "mixfunc" || p.kind.parse::<MaterialKind>().is_ok();
    // A name refers to its last definition before the user.
    let before = |name: &str, user: usize| primitives[..user].iter().rposition(|q| q.name == name);
    // Where an alias chain ends (bounded: each step goes back).
    let target = |mut i: usize| {
        while primitives[i].kind == "alias" {
            match primitives[i].strings.first().and_then(|n| before(n, i)) {
                Some(j) => i = j,
                None => return None,
            }
        }
        Some(i)
    };
    let mut used = vec![false; primitives.len()];
    for (i, p) in primitives.iter().enumerate() {
        let names = match p.kind.as_str() {
            "mixfunc" => 2,
            "alias" => 1,
            _ => 0,
        };
        for name in p.strings.iter().take(names) {
            if let Some(j) = before(name, i) {
                used[j] = true;
            }
        }
    }
    let candidates: Vec<usize> = (0..primitives.len())
        .filter(|&i| !used[i] && target(i).is_some_and(|t| is_material(&primitives[t])))
        .collect();
    match candidates.as_slice() {
        [one] => Ok(*one),
        [] => {
            let theta = primitives.iter().find(|p| {
                p.kind == "BRTDfunc" && p.strings.iter().any(|s| s.ends_with("-theta.cal"))
            });
            Err(RadError {
                path: path.to_string(),
                line: theta.map_or(1, |p| p.line),
                message: match theta {
                    Some(p) => format!(
                        "`{}` is brtf's θ_in-dependent export (a BRTDfunc), which brtf cannot \
                         evaluate; use the static material beside it ({}.rad) (`brtf render \
                         --fit DIR` renders the θ_in-dependent fit)",
                        p.name, p.name
                    ),
                    None => "no plastic, metal, trans, plastic2, metal2 or trans2 material (or \
                             mixfunc of them) in the file"
                        .into(),
                },
            })
        }
        many => {
            let names: Vec<&str> = many.iter().map(|&i| primitives[i].name.as_str()).collect();
            Err(RadError {
                path: path.to_string(),
                line: primitives[many[1]].line,
                message: format!(
                    "several materials ({}); choose one with --name",
                    names.join(", ")
                ),
            })
        }
    }
}

/// The primitives of `material` under the identifier `name`: one
/// primitive as it is; a mixture as its primitives `name.1` … `name.N`,
/// then the nested `mixfunc`s (`name.mixN-1` … `name.mix2`), the one named
/// `name` last, so that a scene after them can use `name`.
pub fn composite_primitives(material: &Composite, name: &str) -> Vec<Primitive> {
    let parts = material.components();
    if let [(_, m)] = parts {
        return vec![primitive_from_material(m, name)];
    }
    let n = parts.len();
    let mut out: Vec<Primitive> = parts
        .iter()
        .enumerate()
        .map(|(k, (_, m))| primitive_from_material(m, &format!("{name}.{}", k + 1)))
        .collect();
    // The shape's own splits when it has them (exact), else the weights'.
    let splits: Vec<f64> = match (material.shape(), material.args()) {
        (Some(shape), Some(args)) if shape.lobes == n => (0..n - 1)
            .map(|j| args[shape.index_of(ShapeArg::Split(j)).expect("a split")])
            .collect(),
        _ => lobe_splits(&parts.iter().map(|(w, _)| *w).collect::<Vec<_>>()),
    };
    let mut background = format!("{name}.{n}");
    for k in (0..n - 1).rev() {
        let id = if k == 0 {
            name.to_string()
        } else {
            format!("{name}.mix{}", k + 1)
        };
        out.push(Primitive {
            modifier: "void".into(),
            kind: "mixfunc".into(),
            name: id.clone(),
            strings: vec![
                format!("{name}.{}", k + 1),
                background,
                fmt_real(splits[k]),
                ".".into(),
            ],
            ints: Vec::new(),
            reals: Vec::new(),
            line: 0,
        });
        background = id;
    }
    out
}
