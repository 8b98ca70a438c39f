//! Any model file of this library, loaded by its `format` tag: a local model (the paper's
//! method), a base-parameter or a globally linearised model (the direct method).

use crate::direct::{BaseModel, GlobalLinearModel};
use crate::document::Document;
use crate::error::{Error, Result};
use crate::local::LocalModel;

/// Any model file of this library, told apart by its `format` tag.
#[derive(Clone, Debug, PartialEq)]
pub enum ModelFile {
    Local(Box<LocalModel>),
    Base(Box<BaseModel>),
    GlobalLinear(Box<GlobalLinearModel>),
}

impl ModelFile {
    /// Parses a model document: the `format` tag picks the kind, then the kind's own checks
    /// run. `source` names the text in errors (a path).
    pub fn from_json(text: &str, source: &str) -> Result<Self> {
        let tag = crate::document::format_tag(text, source)?;
        let kind = tag.split('/').next().unwrap_or_default();
        Ok(if kind == LocalModel::FORMAT {
            ModelFile::Local(Box::new(LocalModel::from_json_in(text, source)?))
        } else if kind == BaseModel::FORMAT {
            ModelFile::Base(Box::new(BaseModel::from_json_in(text, source)?))
        } else if kind == GlobalLinearModel::FORMAT {
            ModelFile::GlobalLinear(Box::new(GlobalLinearModel::from_json_in(text, source)?))
        } else {
            return Err(Error::Json {
                context: source.into(),
                message: format!(
                    "format '{tag}' is not a model; expected {}, {} or {}",
                    LocalModel::FORMAT,
                    BaseModel::FORMAT,
                    GlobalLinearModel::FORMAT
                ),
            });
        })
    }

    /// Reads and parses a model file.
    pub fn load(path: impl AsRef<std::path::Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::from_json(
            &crate::io::read_document(path)?,
            &path.display().to_string(),
        )
    }

    /// The names of the joints the model is for.
    pub fn joint_names(&self) -> &[String] {
        match self {
            ModelFile::Local(m) => &m.joint_names,
            ModelFile::Base(m) => &m.joint_names,
            ModelFile::GlobalLinear(m) => &m.joint_names,
        }
    }
}
