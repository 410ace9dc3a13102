//! Packs the FMUs: zips with `modelDescription.xml` and the one cdylib under each model's
//! name — `binaries/linux64/<modelIdentifier>.so` in `<identifier>.fmu` (FMI 2.0),
//! `binaries/x86_64-linux/<modelIdentifier>.so` in `<identifier>-fmi3.fmu` (FMI 3.0). Also
//! writes the checked-in modelDescription copies.

use crate::model_description::{self, UnknownUnit};
use crate::model_description3;
use crate::table::ModelTable;
use std::fs::{self, File};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

/// Why packing failed.
#[derive(Debug, thiserror::Error)]
pub enum PackError {
    #[error("{}: {source}", path.display())]
    Io { path: PathBuf, source: io::Error },
    #[error("{}: {source}", path.display())]
    Zip {
        path: PathBuf,
        source: zip::result::ZipError,
    },
    #[error(transparent)]
    Unit(#[from] UnknownUnit),
}

fn io(path: &Path) -> impl FnOnce(io::Error) -> PackError + '_ {
    move |source| PackError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// An FMI version's packing: file-name suffix, binaries folder, description generator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Version {
    Fmi2,
    Fmi3,
}

impl Version {
    pub const ALL: [Version; 2] = [Version::Fmi2, Version::Fmi3];

    /// `Quadrotor` (FMI 2.0) or `Quadrotor-fmi3`: the FMU's file stem and the folder of its
    /// checked-in modelDescription.
    pub fn stem(self, table: &ModelTable) -> String {
        match self {
            Version::Fmi2 => table.info.identifier.to_string(),
            Version::Fmi3 => format!("{}-fmi3", table.info.identifier),
        }
    }

    fn platform(self) -> &'static str {
        match self {
            Version::Fmi2 => "linux64",
            Version::Fmi3 => "x86_64-linux",
        }
    }

    /// The modelDescription.xml of `table` in this version.
    pub fn model_description(self, table: &ModelTable) -> Result<String, UnknownUnit> {
        match self {
            Version::Fmi2 => model_description::generate(table),
            Version::Fmi3 => model_description3::generate(table),
        }
    }
}

/// Writes `<out_dir>/<stem>.fmu` holding `library` as the model's binary.
pub fn write_fmu(
    table: &ModelTable,
    version: Version,
    library: &Path,
    out_dir: &Path,
) -> Result<PathBuf, PackError> {
    let xml = version.model_description(table)?;
    let binary = fs::read(library).map_err(io(library))?;
    fs::create_dir_all(out_dir).map_err(io(out_dir))?;
    let path = out_dir.join(format!("{}.fmu", version.stem(table)));
    let file = File::create(&path).map_err(io(&path))?;
    let zip_error = |source| PackError::Zip {
        path: path.clone(),
        source,
    };
    let mut zip = ZipWriter::new(file);
    let options = SimpleFileOptions::default().compression_method(CompressionMethod::Deflated);
    zip.start_file("modelDescription.xml", options.unix_permissions(0o644))
        .map_err(zip_error)?;
    zip.write_all(xml.as_bytes()).map_err(io(&path))?;
    let so = format!(
        "binaries/{}/{}.so",
        version.platform(),
        table.info.identifier
    );
    zip.start_file(so, options.unix_permissions(0o755))
        .map_err(zip_error)?;
    zip.write_all(&binary).map_err(io(&path))?;
    zip.finish().map_err(zip_error)?;
    Ok(path)
}

/// Where the checked-in modelDescription of `table` lives under `dir`.
pub fn model_description_path(dir: &Path, table: &ModelTable, version: Version) -> PathBuf {
    dir.join(version.stem(table)).join("modelDescription.xml")
}

/// Writes `<dir>/<stem>/modelDescription.xml`.
pub fn write_model_description(
    table: &ModelTable,
    version: Version,
    dir: &Path,
) -> Result<PathBuf, PackError> {
    let path = model_description_path(dir, table, version);
    if let Some(parent) = path.parent() {
        fs::create_dir_all(parent).map_err(io(parent))?;
    }
    fs::write(&path, version.model_description(table)?).map_err(io(&path))?;
    Ok(path)
}
