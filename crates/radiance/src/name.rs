//! The default material name of a fit (`brtf fit` without `--name`, and
//! the Python `brtf.fit`).

use crate::identifier;

/// The material name of a fit of these files: their `#sample_name` when
/// all agree, else the longest common start of their file-name stems (cut
/// at a `:`, so `alu:+30+0` and `alu:+45+0` give `alu`), as a Radiance
/// identifier; `fit` when nothing is left.
pub fn default_fit_name(sample_names: &[Option<String>], stems: &[String]) -> String {
    if let Some(Some(first)) = sample_names.first()
        && sample_names.iter().all(|n| n.as_ref() == Some(first))
        && let Some(name) = identifier(first)
    {
        return name;
    }
    let Some(start) = stems.first() else {
        return "fit".into();
    };
    let common = stems.iter().fold(start.clone(), |acc, s| {
        acc.chars()
            .zip(s.chars())
            .take_while(|(a, b)| a == b)
            .map(|(a, _)| a)
            .collect()
    });
    // `alu:+30+0` and `alu:+45+0` share `alu:+`; the identifier drops the `:+`.
    let common = common.split(':').next().unwrap_or_default();
    identifier(common).unwrap_or_else(|| "fit".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_name_then_common_stem_then_fit() {
        let stems = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        let same = vec![Some("Golden_glossy_paper".to_string()); 2];
        assert_eq!(
            default_fit_name(&same, &stems(&["a", "b"])),
            "Golden_glossy_paper"
        );
        let none = vec![None, None];
        assert_eq!(
            default_fit_name(&none, &stems(&["alu:+30+0", "alu:+45+0"])),
            "alu"
        );
        assert_eq!(default_fit_name(&none, &stems(&["x1", "y1"])), "fit");
    }
}
