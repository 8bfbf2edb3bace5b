//! The order of a session's blocks across participants (counterbalancing) and its rest breaks.
//!
//! `counterbalance = "williams"` orders the blocks by a balanced Latin square (Williams 1949): every
//! block comes in every position equally often and, over the square's rows, every block follows
//! every other equally often, which balances first-order carry-over. With `n` blocks the square has
//! `n` rows for even `n` and `2n` for odd `n` (each row and its reverse). `"reverse"` alternates the
//! file's order and its reverse (ABBA across participants). `"none"` (the default) keeps the file's
//! order. A participant's row is the number at the end of the participant ID (`P07` → row 7 mod the
//! number of rows): participants numbered in sequence fill the square's rows in turn. The row and
//! the resulting order are written to `session.json`.
//!
//! `[breaks]`: `every = N` rests before every `N`-th trial of the session, and `between_blocks =
//! true` before the first trial of every block after the first. The observer is told
//! ([`super::Observer::rest`]) before that trial; the simulated observer needs none (the browser
//! page does not show a break screen yet: docs/STUDIES.md, What is not built yet).

use super::file::StudyFile;
use haptic2d::scene::SceneError;

/// How blocks are ordered across participants.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Counterbalance {
    /// The file's order for everyone.
    #[default]
    None,
    /// The file's order, and its reverse for odd rows.
    Reverse,
    /// A balanced Latin square (Williams 1949).
    Williams,
}

/// `[breaks]`: when the session rests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Breaks {
    /// Rest before every `every`-th trial (0: never).
    pub every: u32,
    /// Rest before the first trial of every block after the first.
    pub between_blocks: bool,
}

/// `[breaks]` in a study file.
#[derive(Clone, Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BreaksSection {
    /// Rest before every N-th trial.
    pub every: Option<u32>,
    /// Rest between blocks.
    pub between_blocks: Option<bool>,
}

/// Validates `counterbalance` and `[breaks]`.
pub fn from_file(f: &StudyFile, errs: &mut Vec<SceneError>) -> (Counterbalance, Breaks) {
    let cb = match f.counterbalance.as_deref() {
        None | Some("none") => Counterbalance::None,
        Some("reverse") => Counterbalance::Reverse,
        Some("williams") => Counterbalance::Williams,
        Some(other) => {
            errs.push(SceneError::new(
                "counterbalance".to_string(),
                format!("unknown counterbalancing `{other}`"),
                "counterbalance = \"none\" (default), \"reverse\" (ABBA across participants) or \"williams\" (balanced Latin square)",
            ));
            Counterbalance::None
        }
    };
    let b = f.breaks.clone().unwrap_or_default();
    let every = b.every.unwrap_or(0);
    if b.every == Some(0) || every > 100_000 {
        errs.push(SceneError::new(
            "breaks.every".to_string(),
            format!("{every}"),
            "give the trials between rests, 1 to 100000 (e.g. every = 60), or remove it",
        ));
    }
    let breaks = Breaks {
        every,
        between_blocks: b.between_blocks.unwrap_or(false),
    };
    (cb, breaks)
}

/// Rows of a Williams square of `n` blocks: `n` for even `n`, `2n` for odd.
pub fn williams_rows(n: usize) -> usize {
    if n.is_multiple_of(2) {
        n
    } else {
        2 * n
    }
}

/// Row `r` of the balanced Latin square of `n` blocks (Williams 1949): the first row is
/// `0, 1, n−1, 2, n−2, …`, row `r < n` adds `r` (mod `n`) to it; for odd `n`, rows `n … 2n−1`
/// are the first `n` reversed.
pub fn williams_row(n: usize, r: usize) -> Vec<usize> {
    if n == 0 {
        return Vec::new();
    }
    let r = r % williams_rows(n);
    let first: Vec<usize> = (0..n)
        .map(|k| {
            if k == 0 {
                0
            } else if k % 2 == 1 {
                k.div_ceil(2)
            } else {
                n - k / 2
            }
        })
        .collect();
    let mut row: Vec<usize> = first.iter().map(|&b| (b + r % n) % n).collect();
    if r >= n {
        row.reverse();
    }
    row
}

/// The number at the end of a participant ID (`P07` → 7), the row of the counterbalancing.
pub fn participant_number(id: &str) -> Option<usize> {
    let digits: String = id
        .chars()
        .rev()
        .take_while(char::is_ascii_digit)
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    digits.parse().ok()
}

/// The block order of `participant`: the indices of the study's `n` blocks in the order they run.
pub fn block_order(cb: Counterbalance, n: usize, participant: &str) -> Result<Vec<usize>, String> {
    if cb == Counterbalance::None || n < 2 {
        return Ok((0..n).collect());
    }
    let row = participant_number(participant).ok_or_else(|| {
        format!(
            "participant ID `{participant}` ends in no number, and the study counterbalances its blocks by participant number\n    fix: number the participants, e.g. P01, P02, …"
        )
    })?;
    Ok(match cb {
        Counterbalance::Williams => williams_row(n, row),
        Counterbalance::Reverse if row % 2 == 1 => (0..n).rev().collect(),
        _ => (0..n).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Williams square is a Latin square (each block once per row and once per position) and
    /// balanced for first-order carry-over: over its rows every ordered pair of distinct blocks is
    /// adjacent equally often (once for even `n`, twice for odd `n`).
    #[test]
    fn a_williams_square_is_latin_and_balanced_for_carry_over() {
        for n in 2..=7 {
            let rows = williams_rows(n);
            let sq: Vec<Vec<usize>> = (0..rows).map(|r| williams_row(n, r)).collect();
            for row in &sq {
                let mut s = row.clone();
                s.sort_unstable();
                assert_eq!(s, (0..n).collect::<Vec<_>>(), "n = {n}: {row:?}");
            }
            for pos in 0..n {
                let mut count = vec![0; n];
                for row in &sq {
                    count[row[pos]] += 1;
                }
                assert!(
                    count.iter().all(|&c| c == rows / n),
                    "n = {n}, position {pos}"
                );
            }
            let mut pairs = vec![vec![0; n]; n];
            for row in &sq {
                for w in row.windows(2) {
                    pairs[w[0]][w[1]] += 1;
                }
            }
            let want = rows / n;
            for (a, p) in pairs.iter().enumerate() {
                for (b, &c) in p.iter().enumerate() {
                    if a != b {
                        assert_eq!(c, want, "n = {n}: {a} then {b} {c} times");
                    }
                }
            }
        }
    }

    #[test]
    fn participants_are_rows_by_their_number_and_an_id_without_one_is_refused() {
        assert_eq!(participant_number("P07"), Some(7));
        assert_eq!(participant_number("sub-12"), Some(12));
        assert_eq!(participant_number("anna"), None);
        assert_eq!(
            block_order(Counterbalance::Williams, 4, "P01").unwrap(),
            williams_row(4, 1)
        );
        assert_eq!(
            block_order(Counterbalance::Reverse, 3, "P03").unwrap(),
            vec![2, 1, 0]
        );
        assert_eq!(
            block_order(Counterbalance::Reverse, 3, "P04").unwrap(),
            vec![0, 1, 2]
        );
        let e = block_order(Counterbalance::Williams, 3, "anna").unwrap_err();
        assert!(e.contains("fix:"), "{e}");
        assert_eq!(
            block_order(Counterbalance::None, 3, "anna").unwrap(),
            vec![0, 1, 2]
        );
    }
}
