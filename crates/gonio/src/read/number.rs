//! Decimal number parsing for data rows.
//!
//! This module owns the hot loop of the readers: turning a field like
//! `89.98829` or `-4.574e-06` into an `f64`. Plain decimals with at most 19
//! digits, a mantissa ≤ 2⁵³ and a decimal exponent within ±22
//! take Clinger's exact fast path (one correctly rounded multiplication or
//! division of two exactly representable numbers), which gives the same
//! bits as `str::parse::<f64>`. Everything else (long mantissas, large
//! exponents, `inf`, junk) goes through `str::parse::<f64>`, so results and
//! accepted syntax never differ from the standard library.

/// Exact powers of ten representable in `f64`.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Parses `text` exactly like `text.parse::<f64>()`.
#[inline]
pub(crate) fn parse_f64(text: &str) -> Result<f64, std::num::ParseFloatError> {
    match parse_prefix(text.as_bytes()) {
        Some((v, used)) if used == text.len() => Ok(v),
        _ => text.parse::<f64>(),
    }
}

/// Clinger's fast path on the longest number-like prefix of `bytes`:
/// `Some((value, bytes used))`, or `None` when the fast path does not apply
/// (the caller then falls back to `str::parse`). The value is always finite.
#[inline(always)]
pub(crate) fn parse_prefix(bytes: &[u8]) -> Option<(f64, usize)> {
    let mut i = 0;
    let negative = match bytes.first()? {
        b'-' => {
            i = 1;
            true
        }
        b'+' => {
            i = 1;
            false
        }
        _ => false,
    };
    // Digits are accumulated without per-digit checks (wrapping on
    // overflow); more than 19 digits in all, leading zeros included, falls
    // back to the standard parser before the mantissa is used.
    let (mut mantissa, int_digits) = digits(bytes, &mut i, 0);
    let mut digits_total = int_digits;
    let mut exponent: i32 = 0;
    if bytes.get(i) == Some(&b'.') {
        i += 1;
        let (m, frac_digits) = digits(bytes, &mut i, mantissa);
        mantissa = m;
        digits_total += frac_digits;
        exponent = -i32::try_from(frac_digits).ok()?;
    }
    if digits_total == 0 || digits_total > 19 {
        return None;
    }
    if let Some(&(b'e' | b'E')) = bytes.get(i) {
        i += 1;
        let exp_negative = match bytes.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let start = i;
        let mut e: i32 = 0;
        while let Some(&b) = bytes.get(i) {
            if !b.is_ascii_digit() {
                break;
            }
            if e > 10_000 {
                return None;
            }
            e = e * 10 + i32::from(b - b'0');
            i += 1;
        }
        if i == start {
            return None;
        }
        exponent += if exp_negative { -e } else { e };
    }
    if mantissa > (1u64 << 53) {
        return None;
    }
    let m = mantissa as f64;
    let magnitude = if exponent >= 0 {
        m * *POW10.get(usize::try_from(exponent).ok()?)?
    } else {
        m / *POW10.get(usize::try_from(-exponent).ok()?)?
    };
    Some((if negative { -magnitude } else { magnitude }, i))
}

/// Reads the run of ASCII digits at `bytes[*i..]`, appending them to
/// `mantissa` (wrapping on overflow); returns the new mantissa and the
/// number of digits, and moves `*i` past them. Eight bytes at a time
/// where the text has them (SWAR: one 64-bit load, one digit test, three
/// multiplications), byte by byte near the end.
#[inline(always)]
fn digits(bytes: &[u8], i: &mut usize, mut mantissa: u64) -> (u64, usize) {
    let start = *i;
    while let Some(chunk) = bytes.get(*i..*i + 8) {
        let word = u64::from_le_bytes(chunk.try_into().expect("eight bytes"));
        // Bit 7 of each byte: set where the byte is not a digit. Exact up
        // to and including the first non-digit, which is all that is used.
        let below = word.wrapping_sub(0x3030_3030_3030_3030);
        let above = word.wrapping_add(0x4646_4646_4646_4646);
        let non_digits = (below | above) & 0x8080_8080_8080_8080;
        let count = (non_digits.trailing_zeros() / 8) as usize;
        if count > 0 {
            // The `count` digits (first byte lowest) moved to the top, the
            // bytes below them zero: leading zeros of an 8-digit number.
            let aligned = below << (8 * (8 - count));
            mantissa = mantissa
                .wrapping_mul(POW10_U64[count])
                .wrapping_add(eight_digits(aligned));
        }
        *i += count;
        if count < 8 {
            return (mantissa, *i - start);
        }
    }
    while let Some(&b) = bytes.get(*i) {
        let digit = b.wrapping_sub(b'0');
        if digit > 9 {
            break;
        }
        mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(digit));
        *i += 1;
    }
    (mantissa, *i - start)
}

/// Powers of ten up to 10⁸ as integers.
const POW10_U64: [u64; 9] = [
    1,
    10,
    100,
    1_000,
    10_000,
    100_000,
    1_000_000,
    10_000_000,
    100_000_000,
];

/// The value of eight decimal digits, one per byte (each 0 to 9), the
/// first (most significant) in the lowest byte.
#[inline(always)]
fn eight_digits(digits: u64) -> u64 {
    // Pairs, then quadruples, then the whole (each step halves the count).
    let pairs = digits.wrapping_mul(10).wrapping_add(digits >> 8);
    const MASK: u64 = 0x0000_00FF_0000_00FF;
    let high = (pairs & MASK).wrapping_mul(100 + (1_000_000 << 32));
    let low = ((pairs >> 16) & MASK).wrapping_mul(1 + (10_000 << 32));
    (high.wrapping_add(low) >> 32) & 0xFFFF_FFFF
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agrees_with_std_bit_for_bit() {
        let cases = [
            "0",
            "-0",
            "+0",
            "0.0",
            "89.98829",
            "-4.574e-06",
            "2.138e-06",
            "9.9e+37",
            "1e22",
            "1e23",
            "1e-22",
            "1e-23",
            "123456789012345678",
            "1234567890123456789",
            "12345678901234567890",
            "9007199254740993",
            "0.1",
            "3.",
            ".5",
            "-.5",
            "5e",
            "e5",
            "1e+",
            "--1",
            "1.2.3",
            "",
            "-",
            "+",
            "inf",
            "NaN",
            "0x10",
            "1_0",
            "0.000000000000000000001",
            "4.9e-324",
            "1.7976931348623157e308",
            "00000000000000000000000001.5",
            "1E5",
            "7e-0",
        ];
        for text in cases {
            let ours = parse_f64(text).map(f64::to_bits).ok();
            let std = text.parse::<f64>().map(f64::to_bits).ok();
            assert_eq!(ours, std, "{text:?}");
        }
    }

    proptest::proptest! {
        #[test]
        fn random_decimals_agree_with_std(
            sign in "[+-]?",
            int in "[0-9]{0,22}",
            frac in proptest::option::of("[0-9]{0,22}"),
            exp in proptest::option::of("[eE][+-]?[0-9]{1,4}"),
        ) {
            let text = format!(
                "{sign}{int}{}{}",
                frac.map(|f| format!(".{f}")).unwrap_or_default(),
                exp.unwrap_or_default()
            );
            let ours = parse_f64(&text).map(f64::to_bits).ok();
            let std = text.parse::<f64>().map(f64::to_bits).ok();
            proptest::prop_assert_eq!(ours, std, "{}", text);
        }

        #[test]
        fn prefixes_inside_rows_agree_with_std(
            sign in "[+-]?",
            int in "[0-9]{0,22}",
            frac in proptest::option::of("[0-9]{0,22}"),
            exp in proptest::option::of("[eE][+-]?[0-9]{1,4}"),
            tail in "[ \t\r\n#a-z.0-9]{0,12}",
        ) {
            // Followed by more text, as in a file: the 8-byte digit path.
            let text = format!(
                "{sign}{int}{}{}",
                frac.map(|f| format!(".{f}")).unwrap_or_default(),
                exp.unwrap_or_default()
            );
            let row = format!("{text}\t{tail}");
            if let Some((value, used)) = parse_prefix(row.as_bytes()) {
                let std = row[..used].parse::<f64>().map(f64::to_bits).ok();
                proptest::prop_assert_eq!(Some(value.to_bits()), std, "{:?}", row);
                proptest::prop_assert!(used <= text.len(), "{:?}", row);
            }
        }

        #[test]
        fn any_f64_round_trips(bits in proptest::prelude::any::<u64>()) {
            let v = f64::from_bits(bits);
            proptest::prop_assume!(v.is_finite());
            for text in [format!("{v}"), format!("{v:e}")] {
                proptest::prop_assert_eq!(parse_f64(&text).unwrap().to_bits(), bits);
            }
        }
    }
}
