//! Option words: the one spelling of every choice the command line and
//! the Python package accept (`--residual log`, `residual="log"`).
//!
//! An enum declared with [`option_words!`] gets `Display` (its word),
//! `FromStr` (the word, case-insensitive, with `_` read as `-` so that
//! Python's `solid_angle` and the CLI's `solid-angle` are one word) and
//! [`OptionWords`] (every word, for help texts and clap's value lists).

use std::fmt;

/// A closed set of choices, each with one word.
pub trait OptionWords: Sized + Copy + 'static {
    /// Every choice, in the order of [`OptionWords::WORDS`].
    const ALL: &'static [Self];
    /// The word of each choice.
    const WORDS: &'static [&'static str];
    /// Older spellings still read, never printed.
    const ALIASES: &'static [(&'static str, Self)];
    /// This choice's word.
    fn word(self) -> &'static str;
}

/// A word that names none of the choices.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WordError {
    /// What was given.
    pub found: String,
    /// The words accepted.
    pub expected: &'static [&'static str],
}

impl fmt::Display for WordError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "`{}` is not one of ", self.found)?;
        match self.expected {
            [] => f.write_str("no choices"),
            [one] => f.write_str(one),
            [init @ .., last] => write!(f, "{} or {last}", init.join(", ")),
        }
    }
}

impl std::error::Error for WordError {}

/// Reads `text` as one of `T`'s words or aliases (case-insensitive, `_`
/// as `-`).
pub fn parse_word<T: OptionWords>(text: &str) -> Result<T, WordError> {
    let key = text.trim().replace('_', "-");
    let words = T::WORDS.iter().copied().zip(T::ALL.iter().copied());
    words
        .chain(T::ALIASES.iter().copied())
        .find(|(w, _)| w.eq_ignore_ascii_case(&key))
        .map(|(_, choice)| choice)
        .ok_or_else(|| WordError {
            found: text.to_string(),
            expected: T::WORDS,
        })
}

/// Declares the words of a fieldless enum: `Display`, `FromStr` and
/// [`OptionWords`]. `Variant => "word" | "alias"` also accepts the alias
/// (an older spelling), which is never printed.
///
/// ```
/// #[derive(Debug, Clone, Copy, PartialEq)]
/// enum Fruit { Apple, BloodOrange }
/// brtf_model::option_words!(Fruit { Apple => "apple", BloodOrange => "blood-orange" });
/// assert_eq!("blood_orange".parse::<Fruit>(), Ok(Fruit::BloodOrange));
/// assert_eq!(Fruit::Apple.to_string(), "apple");
/// ```
#[macro_export]
macro_rules! option_words {
    ($ty:ident { $($variant:ident => $word:literal $(| $alias:literal)*),+ $(,)? }) => {
        impl $crate::OptionWords for $ty {
            const ALL: &'static [Self] = &[$($ty::$variant),+];
            const WORDS: &'static [&'static str] = &[$($word),+];
            const ALIASES: &'static [(&'static str, Self)] = &[$($(($alias, $ty::$variant),)*)+];
            fn word(self) -> &'static str {
                match self { $($ty::$variant => $word),+ }
            }
        }
        impl ::std::fmt::Display for $ty {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str($crate::OptionWords::word(*self))
            }
        }
        impl ::std::str::FromStr for $ty {
            type Err = $crate::WordError;
            fn from_str(s: &str) -> ::std::result::Result<Self, Self::Err> {
                $crate::parse_word(s)
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, Copy, PartialEq)]
    enum Shade {
        Light,
        DeepBlue,
        Red,
    }
    option_words!(Shade { Light => "light", DeepBlue => "deep-blue" | "navy", Red => "red" });

    #[test]
    fn words_round_trip_and_accept_python_spelling() {
        for (&shade, &word) in Shade::ALL.iter().zip(Shade::WORDS) {
            assert_eq!(shade.to_string(), word);
            assert_eq!(word.parse::<Shade>(), Ok(shade));
        }
        assert_eq!("deep_blue".parse::<Shade>(), Ok(Shade::DeepBlue));
        assert_eq!(" RED ".parse::<Shade>(), Ok(Shade::Red));
        assert_eq!("navy".parse::<Shade>(), Ok(Shade::DeepBlue));
        assert_eq!(Shade::DeepBlue.to_string(), "deep-blue");
    }

    #[test]
    fn unknown_words_list_the_choices() {
        let err = "green".parse::<Shade>().unwrap_err();
        assert_eq!(
            err.to_string(),
            "`green` is not one of light, deep-blue or red"
        );
    }
}
