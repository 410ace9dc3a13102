//! Why a policy folder or a Policy.fmu's resources cannot be used: the file, and the field
//! when one is to blame.

use std::fmt;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, PartialEq)]
pub struct PolicyError {
    pub file: PathBuf,
    /// The recipe field or network input/output at fault, if one is.
    pub field: Option<String>,
    pub message: String,
}

impl PolicyError {
    pub fn file(file: &Path, message: String) -> Self {
        PolicyError {
            file: file.to_path_buf(),
            field: None,
            message,
        }
    }

    pub fn field(file: &Path, field: &str, message: String) -> Self {
        PolicyError {
            file: file.to_path_buf(),
            field: Some(field.to_string()),
            message,
        }
    }
}

impl fmt::Display for PolicyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.field {
            Some(field) => write!(f, "{}: {field}: {}", self.file.display(), self.message),
            None => write!(f, "{} {}", self.file.display(), self.message),
        }
    }
}

impl std::error::Error for PolicyError {}
