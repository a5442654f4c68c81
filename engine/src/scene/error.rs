//! The one error type for everything a scene reads: its message always says which file (when
//! there is one) and what is wrong with it, so a user can fix the input without a debugger.
use crate::host_memory::OutOfHostMemory;
use std::fmt;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct SceneError {
    file: Option<PathBuf>,
    problem: String,
    /// The machine had no memory for the data: not the data's fault.
    out_of_memory: bool,
}

impl SceneError {
    /// A problem with the named file.
    pub fn in_file(file: impl Into<PathBuf>, problem: impl Into<String>) -> SceneError {
        SceneError { file: Some(file.into()), problem: problem.into(), out_of_memory: false }
    }

    /// A problem with data that came from no file (a built-in scene, an API call).
    pub fn invalid(problem: impl Into<String>) -> SceneError {
        SceneError { file: None, problem: problem.into(), out_of_memory: false }
    }

    /// Prefixes the place the problem is at, e.g. `group 0 ("floor")`. A file this error already
    /// names moves into the message, so nested errors read
    /// `scene.json: group 0 ("teapot"): mesh 0: teapot.obj: ...` once attributed.
    pub(crate) fn within(self, place: &str) -> SceneError {
        SceneError { file: None, problem: format!("{place}: {self}"), ..self }
    }

    /// Names `file` as the file at fault, keeping any other file already named in the message
    /// (the same file is named once: a glTF file read alone is both the scene and the file).
    pub(crate) fn attributed_to(self, file: &Path) -> SceneError {
        let problem = match &self.file {
            Some(named) if named != file => self.to_string(),
            _ => self.problem,
        };
        SceneError { file: Some(file.to_path_buf()), problem, ..self }
    }

    pub fn file(&self) -> Option<&Path> {
        self.file.as_deref()
    }

    /// Whether the data was refused for want of memory (see [`crate::host_memory`]), not for
    /// what it holds.
    pub fn out_of_memory(&self) -> bool {
        self.out_of_memory
    }

    pub fn problem(&self) -> &str {
        &self.problem
    }
}

impl From<OutOfHostMemory> for SceneError {
    fn from(error: OutOfHostMemory) -> SceneError {
        SceneError { file: None, problem: error.to_string(), out_of_memory: true }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.file {
            Some(file) => write!(f, "{}: {}", file.display(), self.problem),
            None => f.write_str(&self.problem),
        }
    }
}

/// The longest name or text from an input that a message quotes whole, in characters.
pub const CLIP_CHARS: usize = 200;

/// `text` as a message quotes it: whole up to [`CLIP_CHARS`] characters, else its first
/// [`CLIP_CHARS`] and how many more there are (a 100 MB name must not make a 100 MB message).
pub fn clip(text: &str) -> std::borrow::Cow<'_, str> {
    match text.char_indices().nth(CLIP_CHARS) {
        None => text.into(),
        Some((end, _)) => {
            let more = text[end..].chars().count();
            format!("{}… ({more} more characters)", &text[..end]).into()
        }
    }
}

/// A whole message as the command line and the C ABI show it: every run of non-blank
/// characters clipped as [`clip`] clips a text. Names and values quoted by code that never
/// clipped them (a parser's "unknown field `…`", a path from an argument) stay bounded too.
pub fn clip_message(message: &str) -> std::borrow::Cow<'_, str> {
    // No run can be longer than the whole; bytes bound characters.
    if message.len() <= CLIP_CHARS {
        return message.into();
    }
    let mut clipped = String::new();
    for piece in message.split_inclusive(char::is_whitespace) {
        let word = piece.trim_end_matches(char::is_whitespace);
        clipped.push_str(&clip(word));
        clipped.push_str(&piece[word.len()..]);
    }
    clipped.into()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_words_of_a_message_are_clipped_and_the_rest_kept() {
        let long = "x".repeat(CLIP_CHARS + 7);
        let message = format!("unknown field `{long}`, expected one of `name`\n  at line 1");
        let expected = format!(
            "unknown field `{}… (10 more characters) expected one of `name`\n  at line 1",
            "x".repeat(CLIP_CHARS - 1)
        );
        assert_eq!(clip_message(&message), expected);
        assert_eq!(clip_message("short message"), "short message");
    }

    #[test]
    fn long_texts_are_clipped_with_a_count() {
        assert_eq!(clip("short"), "short");
        let long = "é".repeat(CLIP_CHARS + 5);
        assert_eq!(clip(&long), format!("{}… (5 more characters)", "é".repeat(CLIP_CHARS)));
    }
}
