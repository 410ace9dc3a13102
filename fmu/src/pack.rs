//! Packs an FMU: a zip with `modelDescription.xml` and
//! `binaries/linux64/<modelIdentifier>.so` (the one cdylib, under each model's name). Also writes the checked-in modelDescription
//! copies.

use crate::model::ModelTable;
use crate::model_description::{self, UnknownUnit};
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

/// Writes `<out_dir>/<identifier>.fmu` holding `library` as the model's binary.
pub fn write_fmu(table: &ModelTable, library: &Path, out_dir: &Path) -> Result<PathBuf, PackError> {
    let xml = model_description::generate(table)?;
    let binary = fs::read(library).map_err(io(library))?;
    fs::create_dir_all(out_dir).map_err(io(out_dir))?;
    let path = out_dir.join(format!("{}.fmu", table.info.identifier));
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
    let so = format!("binaries/linux64/{}.so", table.info.identifier);
    zip.start_file(so, options.unix_permissions(0o755))
        .map_err(zip_error)?;
    zip.write_all(&binary).map_err(io(&path))?;
    zip.finish().map_err(zip_error)?;
    Ok(path)
}

/// Where the checked-in modelDescription of `table` lives under `dir`.
pub fn model_description_path(dir: &Path, table: &ModelTable) -> PathBuf {
    dir.join(table.info.identifier).join("modelDescription.xml")
}

/// Writes `<dir>/<identifier>/modelDescription.xml`.
pub fn write_model_description(table: &ModelTable, dir: &Path) -> Result<PathBuf, PackError> {
    let path = model_description_path(dir, table);
    if let Some(parent) = path.parent() {
        fs::create_dir_all(parent).map_err(io(parent))?;
    }
    fs::write(&path, model_description::generate(table)?).map_err(io(&path))?;
    Ok(path)
}
