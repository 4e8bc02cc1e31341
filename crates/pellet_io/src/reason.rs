//! An operating-system error in plain words: "is a directory", not "Is a directory (os error
//! 21)"; the error number means nothing to a user.

/// What went wrong, in words a user reads: the OS's text without its error number, or for the
/// kinds whose OS text is cryptic on its own, a sentence that says what to do.
pub fn plain_reason(e: &std::io::Error) -> String {
    use std::io::ErrorKind as K;
    match e.kind() {
        K::IsADirectory => "is a directory, not a file; give a file name".into(),
        K::NotADirectory => "a part of the path is a file, not a directory".into(),
        K::AlreadyExists => "already exists".into(),
        _ => {
            let text = e.to_string();
            let cut = match text.rfind(" (os error ") {
                Some(at) if text.ends_with(')') => at,
                _ => text.len(),
            };
            text[..cut].to_string()
        }
    }
}

/// At most 40 characters of what a file holds, control characters as `?`: a message quotes
/// the file's text, but a damaged file's field or line may be megabytes long.
pub(crate) fn shown_field(s: &str) -> String {
    let mut out: String = s.chars().take(40).map(|c| if c.is_control() { '?' } else { c }).collect();
    if s.chars().nth(40).is_some() {
        out.push('…');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::plain_reason;

    #[test]
    fn os_error_numbers_are_left_out() {
        let dir = std::io::Error::from_raw_os_error(21);
        assert_eq!(plain_reason(&dir), "is a directory, not a file; give a file name");
        assert_eq!(plain_reason(&std::io::Error::from_raw_os_error(17)), "already exists");
        assert_eq!(plain_reason(&std::io::Error::from_raw_os_error(2)), "No such file or directory");
        assert_eq!(plain_reason(&std::io::Error::other("kept as it is")), "kept as it is");
    }
}
