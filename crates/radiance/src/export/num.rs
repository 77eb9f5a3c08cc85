//! Number formatting for Radiance text: the shortest decimal that reads
//! back as the same `f64`, in plain or exponent form, whichever is shorter.

/// Shortest round-trip text of `x` (`-0` prints as `0`).
pub(crate) fn num(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    let plain = format!("{x}");
    let exp = format!("{x:e}");
    if exp.len() < plain.len() { exp } else { plain }
}

/// `x` rounded to `digits` significant digits, for human-readable comments.
pub(crate) fn sig(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return num(x);
    }
    let magnitude = x.abs().log10().floor() as i32;
    let decimals = (digits as i32 - 1 - magnitude).max(0) as usize;
    if !(-4..=6).contains(&magnitude) {
        return format!("{:.*e}", digits.saturating_sub(1), x);
    }
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shortest_round_trip() {
        for x in [0.05, 1e-7, -2.5e-12, 123456.789, 0.1 + 0.2, 1.0 / 3.0, -0.0] {
            let s = num(x);
            assert_eq!(s.parse::<f64>().unwrap(), x, "{s}");
        }
        assert_eq!(num(0.05), "0.05");
        assert_eq!(num(1e-7), "1e-7");
        assert_eq!(num(-0.0), "0");
        assert_eq!(sig(0.123456, 3), "0.123");
        assert_eq!(sig(0.5, 3), "0.5");
        assert_eq!(sig(12.0, 3), "12");
        assert_eq!(sig(1.5e-7, 2), "1.5e-7");
    }
}
