//! Byte mutations, with the values that break parsers: bit flips, interesting bytes,
//! deletions, insertions and splices from another input, truncation, and numbers
//! replaced by the ones range checks forget (NaN, infinities, 1e38, −1, 2³¹).

/// A small, fast, seedable generator (xorshift64*, Vigna 2016): runs repeat from
/// their seed.
pub struct Rng(u64);

impl Rng {
    /// A generator started from `seed` (0 is replaced, xorshift needs a non-zero state).
    pub fn new(seed: u64) -> Self {
        Rng(seed.max(1))
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// A number in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 { 0 } else { (self.next_u64() % n as u64) as usize }
    }
}

/// Text a target's format gives meaning to, inserted whole by the mutator: keys,
/// punctuation, flag names.
pub type Hints = &'static [&'static str];

/// Numbers that range checks forget.
const NUMBERS: &[&str] = &[
    "nan",
    "-nan",
    "inf",
    "-inf",
    "0",
    "-0",
    "-1",
    "1e38",
    "-1e38",
    "1e-45",
    "2147483648",
    "-2147483649",
    "4294967296",
    "18446744073709551616",
    "0.5",
    "90",
    "180",
    "16385",
    "65536",
];

/// Bytes that structure text formats.
const BYTES: &[u8] = b"\0\n\r\t \"'[]{}=,.:-+#\\0123456789eE\xff\x7f";

/// `base` changed by one to four stacked mutations, some taking bytes from `other`.
pub fn mutate(base: &[u8], other: &[u8], hints: Hints, rng: &mut Rng) -> Vec<u8> {
    let mut out = base.to_vec();
    for _ in 0..1 + rng.below(4) {
        let len = out.len();
        match rng.below(8) {
            0 if len > 0 => {
                let i = rng.below(len);
                out[i] ^= 1 << rng.below(8);
            }
            1 if len > 0 => {
                let i = rng.below(len);
                out[i] = BYTES[rng.below(BYTES.len())];
            }
            2 if len > 0 => {
                let start = rng.below(len);
                let end = (start + 1 + rng.below(16)).min(len);
                out.drain(start..end);
            }
            3 if !other.is_empty() => {
                let start = rng.below(other.len());
                let end = (start + 1 + rng.below(64)).min(other.len());
                let at = rng.below(len + 1);
                out.splice(at..at, other[start..end].iter().copied());
            }
            4 => replace_a_number(&mut out, rng),
            5 if !hints.is_empty() => {
                let at = rng.below(len + 1);
                out.splice(at..at, hints[rng.below(hints.len())].bytes());
            }
            6 if len > 0 => out.truncate(rng.below(len)),
            _ => {
                let at = rng.below(len + 1);
                out.insert(at, BYTES[rng.below(BYTES.len())]);
            }
        }
    }
    out
}

/// Replaces one run of digits (with its sign, point and exponent) by a value from
/// [`NUMBERS`], or inserts one where there is none.
fn replace_a_number(out: &mut Vec<u8>, rng: &mut Rng) {
    let value = NUMBERS[rng.below(NUMBERS.len())].as_bytes();
    let starts: Vec<usize> = (0..out.len())
        .filter(|&i| {
            out[i].is_ascii_digit() && (i == 0 || !(out[i - 1].is_ascii_alphanumeric() || out[i - 1] == b'.'))
        })
        .collect();
    if starts.is_empty() {
        let at = rng.below(out.len() + 1);
        out.splice(at..at, value.iter().copied());
        return;
    }
    let mut start = starts[rng.below(starts.len())];
    if start > 0 && out[start - 1] == b'-' {
        start -= 1;
    }
    let mut end = start + 1;
    while end < out.len() && (out[end].is_ascii_digit() || b".eE-+_".contains(&out[end])) {
        end += 1;
    }
    out.splice(start..end, value.iter().copied());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_repeat_from_their_seed_and_numbers_are_replaced_whole() {
        let (mut a, mut b) = (Rng::new(7), Rng::new(7));
        let base = b"elevation = 45.5\nazimuth = -10\n";
        for _ in 0..100 {
            assert_eq!(mutate(base, base, &[], &mut a), mutate(base, base, &[], &mut b));
        }
        let mut rng = Rng::new(3);
        for _ in 0..50 {
            let mut text = b"x = 12.5e3".to_vec();
            replace_a_number(&mut text, &mut rng);
            let value = std::str::from_utf8(&text[4..]).unwrap();
            assert!(NUMBERS.contains(&value), "{value}");
        }
    }
}
