//! Packs the FMUs: zips with `modelDescription.xml` and the one cdylib under each model's
//! name — `binaries/linux64/<modelIdentifier>.so` in `<identifier>.fmu` (FMI 2.0),
//! `binaries/x86_64-linux/<modelIdentifier>.so` in `<identifier>-fmi3.fmu` (FMI 3.0). Also
//! writes the checked-in modelDescription copies.

use crate::api::Api;
use crate::model_description::generate;
use crate::table::ModelTable;
use std::error::Error;
use std::fs::{self, File};
use std::io::Write;
use std::path::{Path, PathBuf};
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

/// Why packing failed: the file and what went wrong with it (I/O or zip).
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", path.display())]
pub struct PackError {
    pub path: PathBuf,
    pub source: Box<dyn Error + Send + Sync>,
}

fn at<E: Into<Box<dyn Error + Send + Sync>>>(path: &Path) -> impl FnOnce(E) -> PackError + '_ {
    move |e| PackError {
        path: path.to_path_buf(),
        source: e.into(),
    }
}

/// `Quadrotor` (FMI 2.0) or `Quadrotor-fmi3`: the FMU's file stem and the folder of its
/// checked-in modelDescription.
pub fn stem(table: &ModelTable, version: Api) -> String {
    match version {
        Api::Fmi2 => table.info.identifier.to_string(),
        Api::Fmi3 => format!("{}-fmi3", table.info.identifier),
    }
}

/// Writes `<out_dir>/<stem>.fmu` holding `library` as the model's binary.
pub fn write_fmu(
    table: &ModelTable,
    version: Api,
    library: &Path,
    out_dir: &Path,
) -> Result<PathBuf, PackError> {
    fs::create_dir_all(out_dir).map_err(at(out_dir))?;
    let path = out_dir.join(format!("{}.fmu", stem(table, version)));
    write_archive(table, version, library, &path, &[])?;
    Ok(path)
}

/// Writes the FMU `path`: the modelDescription, `library` as the model's binary and
/// `resources` (file name, bytes) under `resources/`. The archive is written next to `path`
/// and renamed onto it once complete, so a failure leaves no partial FMU at `path`.
pub fn write_archive(
    table: &ModelTable,
    version: Api,
    library: &Path,
    path: &Path,
    resources: &[(&str, &[u8])],
) -> Result<(), PackError> {
    let xml = generate(table, version);
    let binary = fs::read(library).map_err(at(library))?;
    let partial = path.with_extension("fmu.partial");
    let written = write_zip(table, version, &xml, &binary, resources, &partial);
    if written.is_err() {
        let _ = fs::remove_file(&partial);
    }
    written?;
    fs::rename(&partial, path).map_err(at(path))
}

fn write_zip(
    table: &ModelTable,
    version: Api,
    xml: &str,
    binary: &[u8],
    resources: &[(&str, &[u8])],
    path: &Path,
) -> Result<(), PackError> {
    let file = File::create(path).map_err(at(path))?;
    let mut zip = ZipWriter::new(file);
    let options = SimpleFileOptions::default().compression_method(CompressionMethod::Deflated);
    zip.start_file("modelDescription.xml", options.unix_permissions(0o644))
        .map_err(at(path))?;
    zip.write_all(xml.as_bytes()).map_err(at(path))?;
    let platform = match version {
        Api::Fmi2 => "linux64",
        Api::Fmi3 => "x86_64-linux",
    };
    let so = format!("binaries/{platform}/{}.so", table.info.identifier);
    zip.start_file(so, options.unix_permissions(0o755))
        .map_err(at(path))?;
    zip.write_all(binary).map_err(at(path))?;
    for (name, bytes) in resources {
        zip.start_file(format!("resources/{name}"), options.unix_permissions(0o644))
            .map_err(at(path))?;
        zip.write_all(bytes).map_err(at(path))?;
    }
    zip.finish().map_err(at(path))?;
    Ok(())
}

/// Where the checked-in modelDescription of `table` lives under `dir`.
pub fn model_description_path(dir: &Path, table: &ModelTable, version: Api) -> PathBuf {
    dir.join(stem(table, version)).join("modelDescription.xml")
}

/// Writes `<dir>/<stem>/modelDescription.xml`.
pub fn write_model_description(
    table: &ModelTable,
    version: Api,
    dir: &Path,
) -> Result<PathBuf, PackError> {
    let path = model_description_path(dir, table, version);
    if let Some(parent) = path.parent() {
        fs::create_dir_all(parent).map_err(at(parent))?;
    }
    fs::write(&path, generate(table, version)).map_err(at(&path))?;
    Ok(path)
}
