//! Numbers as the CSV writes them: the shortest text that reads back to the same `f64`, laid
//! out as Rust's `{:?}` lays it out (fixed notation from 1e-4 up to 1e16, else `1.5e-7`,
//! `1e16`). The digits come from `zmij` (Schubfach; several times faster than `core::fmt`'s,
//! which took a tenth of a two-bar run); only its layout differs, in two places: it writes
//! exponents with a sign (`1e+16`) and the decade from 1e-5 to 1e-4 in fixed notation
//! (`0.000015`).

/// Appends `x` to `line`, byte for byte as `format!("{x:?}")` writes it.
pub(crate) fn push(line: &mut Vec<u8>, buf: &mut zmij::Buffer, x: f64) {
    if !x.is_finite() || may_tie(x) {
        use std::io::Write as _;
        let _ = write!(line, "{x:?}");
        return;
    }
    let s = buf.format_finite(x).as_bytes();
    let (sign, body) = match s.split_first() {
        Some((b'-', rest)) => (&s[..1], rest),
        _ => (&s[..0], s),
    };
    if let Some(digits) = body.strip_prefix(b"0.0000".as_slice()) {
        // The one decade `zmij` writes fixed and `{:?}` does not: 1e-5 <= |x| < 1e-4.
        if digits.first().is_some_and(|d| *d != b'0') {
            line.extend_from_slice(sign);
            line.push(digits[0]);
            if digits.len() > 1 {
                line.push(b'.');
                line.extend_from_slice(&digits[1..]);
            }
            line.extend_from_slice(b"e-5");
            return;
        }
    }
    // A positive exponent's sign, within the last five bytes (`e+308`).
    let tail = s.len().saturating_sub(5);
    match s[tail..].iter().position(|&b| b == b'+') {
        Some(plus) => {
            line.extend_from_slice(&s[..tail + plus]);
            line.extend_from_slice(&s[tail + plus + 1..]);
        }
        None => line.extend_from_slice(s),
    }
}

/// Whether `x`'s exact decimal expansion may have 18 significant digits or fewer: then two
/// shortest texts can be equally near it (1658206780088562.25: `.2` and `.3`), and `zmij` and
/// `{:?}` break the tie differently. `x = m 2^e` with `m` odd has `m 5^-e` as its digits
/// when `e < 0`; values with `e >= 0` are integers (at most 2^53 exactly, or larger). Both
/// are rare in a motion's outputs, and `{:?}` writes them.
fn may_tie(x: f64) -> bool {
    let bits = x.to_bits();
    let (exponent, fraction) = (((bits >> 52) & 0x7ff) as i64, bits & ((1u64 << 52) - 1));
    let (m, e) = if exponent == 0 {
        (fraction, -1074)
    } else {
        (fraction | (1u64 << 52), exponent - 1075)
    };
    if m == 0 {
        return false;
    }
    let (m, e) = (m >> m.trailing_zeros(), e + i64::from(m.trailing_zeros()));
    if e >= 0 {
        return true;
    }
    // A lower bound of log10(m 5^-e).
    let digits =
        f64::from(63 - m.leading_zeros()) * std::f64::consts::LOG10_2 - e as f64 * 5f64.log10();
    digits < 18.0
}

#[cfg(test)]
mod tests {
    use super::push;

    fn same(x: f64, buf: &mut zmij::Buffer, line: &mut Vec<u8>) {
        line.clear();
        push(line, buf, x);
        assert_eq!(String::from_utf8_lossy(line), format!("{x:?}"), "{x:e}");
    }

    /// Every layout `{:?}` has: zero, both notations and their edges, the decade `zmij` lays
    /// out otherwise, subnormals, the extremes, non-finite values.
    #[test]
    fn laid_out_as_debug_at_the_edges() {
        let (mut buf, mut line) = (zmij::Buffer::new(), Vec::new());
        let edges = [
            0.0,
            -0.0,
            1.0,
            0.1,
            100.0,
            1e-5,
            1.5e-5,
            -9.999999999999999e-5,
            1e-4,
            1.0000000000000002e-4,
            0.00012345,
            9.999999999999998e15,
            1e16,
            -1.2345e16,
            1e21,
            1e-7,
            5e-324,
            2.2250738585072014e-308,
            f64::MAX,
            f64::MIN_POSITIVE,
            1658206780088562.2,
            0.5,
            -0.375,
            9007199254740994.0,
            1.5e300,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for x in edges {
            same(x, &mut buf, &mut line);
        }
        // Each decade's ends and middle, both signs.
        for e in -320..=308 {
            for m in [1.0, 1.5, 9.999999999999998] {
                let x = m * 10f64.powi(e);
                same(x, &mut buf, &mut line);
                same(-x, &mut buf, &mut line);
            }
        }
    }

    /// Random bit patterns (a fixed xorshift sequence), and random values near the motions'
    /// magnitudes.
    #[test]
    fn laid_out_as_debug_for_random_values() {
        let (mut buf, mut line) = (zmij::Buffer::new(), Vec::new());
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for _ in 0..200_000 {
            same(f64::from_bits(next()), &mut buf, &mut line);
            let unit = (next() >> 11) as f64 / (1u64 << 53) as f64;
            let decade = (next() % 24) as i32 - 12;
            same((unit - 0.5) * 10f64.powi(decade), &mut buf, &mut line);
        }
        // Short expansions, where two shortest texts tie: quarters and eighths near 1e15,
        // integers past 2^53, and a few binary fractions.
        for k in 0..100_000u64 {
            let n = (1u64 << 50) + k * 7_919;
            for x in [
                n as f64 / 4.0,
                n as f64 / 8.0,
                (n << 4) as f64,
                k as f64 / 1024.0,
            ] {
                same(x, &mut buf, &mut line);
            }
        }
    }
}
