//! What the command lines share: ericw-tools' single-dash spellings of long options, and (in
//! [`crate::progress::terminal`]) progress drawn as a bar.

/// ericw-tools writes long options with one dash (`-extra4`); clap wants two. Negative numbers
/// and short flags (`-h`) are left alone. The first word (the program name) is kept as it is.
pub fn normalise_single_dash(args: impl Iterator<Item = String>) -> Vec<String> {
    args.enumerate()
        .map(|(i, a)| {
            let is_ericw_long = i > 0
                && a.len() > 2
                && a.starts_with('-')
                && !a.starts_with("--")
                && a[1..].starts_with(|c: char| c.is_ascii_alphabetic())
                && a[1..]
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
            if is_ericw_long { format!("-{a}") } else { a }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_dash_long_options_become_double_dash() {
        let args = [
            "slipgate", "light", "-extra4", "-soft", "-h", "--pos", "-100", "x.bsp",
        ];
        let out = normalise_single_dash(args.iter().map(|s| s.to_string()));
        assert_eq!(
            out,
            [
                "slipgate", "light", "--extra4", "--soft", "-h", "--pos", "-100", "x.bsp"
            ]
        );
    }
}
