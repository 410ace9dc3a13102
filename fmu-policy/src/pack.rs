//! Packs a policy folder (recipe.json and its ONNX network) into Policy.fmu (FMI 2.0) and its
//! FMI 3.0 twin: the folder is loaded and checked first (recipe fields, the network's input
//! and output sizes against the recipe), so a bad folder writes nothing.

use crate::catalog::load;
use crate::catalog::table_of;
use crate::error::PolicyError;
use crate::recipe::RECIPE_FILE;
use flyloop_fmu::api::Api;
use flyloop_fmu::pack::write_archive;
use std::path::{Path, PathBuf};

/// The FMI 3.0 twin of the FMU `out`: `<stem>-fmi3.fmu` next to it.
pub fn fmi3_path(out: &Path) -> PathBuf {
    let stem = out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    out.with_file_name(format!("{stem}-fmi3.fmu"))
}

/// Writes `out` (FMI 2.0) and [`fmi3_path`] (FMI 3.0) from the policy in `folder`, with
/// `library` (libflyloop_fmu_policy.so) as their binary; returns the two paths.
pub fn pack(folder: &Path, library: &Path, out: &Path) -> Result<[PathBuf; 2], PolicyError> {
    let loaded = load(folder)?;
    let network_file = loaded.recipe.network.clone();
    let read = |name: &str| {
        let path = folder.join(name);
        std::fs::read(&path).map_err(|e| PolicyError::file(&path, format!("cannot be read: {e}")))
    };
    let (recipe, network) = (read(RECIPE_FILE)?, read(&network_file)?);
    if !library.is_file() {
        return Err(PolicyError::file(
            library,
            "is not the built policy library".to_string(),
        ));
    }
    let table = table_of(loaded);
    let resources: [(&str, &[u8]); 2] = [(RECIPE_FILE, &recipe), (&network_file, &network)];
    let paths = [out.to_path_buf(), fmi3_path(out)];
    for (version, path) in [Api::Fmi2, Api::Fmi3].into_iter().zip(&paths) {
        write_archive(&table.table, version, library, path, &resources)
            .map_err(|e| PolicyError::file(path, format!("cannot be written: {e}")))?;
    }
    Ok(paths)
}
