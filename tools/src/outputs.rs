//! Output paths checked before the work that fills them: a wrong extension or a folder that
//! does not exist fails at once, not after a long render or reference.
use anyhow::{bail, Result};
use std::path::Path;

/// Checks that `path`, given as `flag`, ends in one of `extensions` and lies in an existing folder.
pub fn check(path: &Path, flag: &str, extensions: &[&str]) -> Result<()> {
    let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !extension.is_some_and(|e| extensions.contains(&e.as_str())) {
        let names: Vec<String> = extensions.iter().map(|e| format!(".{e}")).collect();
        bail!("{flag} {}: the file must end in {}", path.display(), names.join(" or "));
    }
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !folder.is_dir() {
        bail!("{flag} {}: the folder {} does not exist", path.display(), folder.display());
    }
    Ok(())
}
