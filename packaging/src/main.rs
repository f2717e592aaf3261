//! `cargo run --release -p packaging`: builds the kerf cdylib in release mode
//! and writes `target/fmu/kerf.fmu`:
//!
//! ```text
//! modelDescription.xml
//! binaries/linux64/kerf.so          (target/release/libkerf.so)
//! documentation/index.html          (packaging/doc/index.html + variable table from the XML)
//! resources/README.txt              (packaging/resources/README.txt)
//! ```
//!
//! The archive is deterministic: fixed entry order, timestamps and permissions.
//!
//! `cargo run --release -p packaging -- --layout FILE.json [--drive head|discs]
//! [--out PATH]` writes a cutterhead FMU instead (`target/fmu/NAME.fmu`, NAME
//! from the layout): the same binary, a modelDescription.xml generated from
//! kerf's and the layout (`head.rs`), and `resources/head.json` (GUID, drive,
//! layout) that tells the binary it is that head.

mod head;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, DateTime, ZipWriter};

pub(crate) type Res<T> = Result<T, String>;

fn main() -> ExitCode {
    match run() {
        Ok(path) => {
            println!("{}", path.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("packaging: {e}");
            ExitCode::FAILURE
        }
    }
}

fn read(path: &Path) -> Res<Vec<u8>> {
    std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))
}

struct Args {
    layout: Option<PathBuf>,
    drive: kerf::core::head::Drive,
    out: Option<PathBuf>,
}

fn args() -> Res<Args> {
    let mut a = Args {
        layout: None,
        drive: kerf::core::head::Drive::Head,
        out: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(k) = it.next() {
        let mut val = || it.next().ok_or_else(|| format!("{k} needs a value"));
        match k.as_str() {
            "--layout" => a.layout = Some(PathBuf::from(val()?)),
            "--drive" => {
                a.drive = match val()?.as_str() {
                    "head" => kerf::core::head::Drive::Head,
                    "discs" => kerf::core::head::Drive::Discs,
                    other => return Err(format!("--drive {other}: must be head or discs")),
                }
            }
            "--out" => a.out = Some(PathBuf::from(val()?)),
            other => {
                return Err(format!(
                    "unknown argument {other} (usage: packaging [--layout FILE.json [--drive head|discs]] [--out PATH])"
                ))
            }
        }
    }
    Ok(a)
}

fn run() -> Res<PathBuf> {
    let args = args()?;
    // check the layout before the (long) build
    let layout = match &args.layout {
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| format!("layout {}: cannot read: {e}", p.display()))?;
            let l = kerf::core::layout::parse(&text, &p.display().to_string())
                .map_err(|e| e.to_string())?;
            Some((l, text))
        }
        None => None,
    };
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let root = here
        .parent()
        .ok_or("packaging has no parent directory")?
        .to_path_buf();
    if !root.join("modelDescription/modelDescription.xml").is_file() {
        return Err(format!("{} is not the kerf workspace root", root.display()));
    }
    build_library(&root)?;
    let target = target_dir(&root);

    let so = read(&target.join("release/libkerf.so"))?;
    let xml = String::from_utf8(read(&root.join("modelDescription/modelDescription.xml"))?)
        .map_err(|_| "modelDescription.xml is not UTF-8")?;
    let template = String::from_utf8(read(&here.join("doc/index.html"))?)
        .map_err(|_| "index.html is not UTF-8")?;
    if !template.contains("<!--VARIABLES-->") {
        return Err("packaging/doc/index.html lacks the <!--VARIABLES--> marker".into());
    }
    let readme = read(&here.join("resources/README.txt"))?;
    let mut extra: Vec<(&str, Vec<u8>)> = Vec::new();
    let (xml, name) = match &layout {
        None => (xml, "kerf".to_string()),
        Some((l, text)) => {
            let file = args.layout.as_ref().unwrap().display().to_string();
            let (head_xml, guid) = head::model_description(&xml, l, args.drive, &file)?;
            let manifest = kerf::fmi2::head_md::manifest(text, args.drive, &guid);
            extra.push(("resources/head.json", manifest.into_bytes()));
            extra.push(("resources/layout.json", text.clone().into_bytes()));
            (head_xml, l.name.clone())
        }
    };
    let html = template.replace("<!--VARIABLES-->", &variable_table(&xml)?);

    let out = match &args.out {
        Some(p) => p.clone(),
        None => target.join("fmu").join(format!("{name}.fmu")),
    };
    let entries: [(&str, &[u8], u32); 4] = [
        ("modelDescription.xml", xml.as_bytes(), 0o644),
        ("binaries/linux64/kerf.so", &so, 0o755),
        ("documentation/index.html", html.as_bytes(), 0o644),
        ("resources/README.txt", &readme, 0o644),
    ];
    write_fmu(
        &out,
        entries
            .into_iter()
            .chain(extra.iter().map(|(n, d)| (*n, d.as_slice(), 0o644))),
    )?;
    Ok(out)
}

/// Builds the FMU's library in release (and packaging with it: the same
/// package set as `cargo run -p packaging`, one feature resolution, so kerf
/// is not built twice).
fn build_library(root: &Path) -> Res<()> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let status = Command::new(&cargo)
        .current_dir(root)
        .args(["build", "--release", "-p", "kerf", "-p", "packaging"])
        .status()
        .map_err(|e| format!("cannot run {}: {e}", cargo.to_string_lossy()))?;
    if !status.success() {
        return Err(format!(
            "cargo build --release -p kerf -p packaging failed ({status})"
        ));
    }
    Ok(())
}

/// Cargo's target directory: `CARGO_TARGET_DIR` (relative to the workspace
/// root), or `target` there.
fn target_dir(root: &Path) -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"));
    if target.is_relative() {
        root.join(target)
    } else {
        target
    }
}

/// Writes the FMU archive `out` with the standard directories and
/// `entries` (name, bytes, unix mode), deflated, with fixed times so that
/// the same inputs give the same bytes; through a temporary file, so a
/// failed write leaves no partial FMU.
fn write_fmu<'a>(out: &Path, entries: impl Iterator<Item = (&'a str, &'a [u8], u32)>) -> Res<()> {
    let out_dir = out
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."));
    std::fs::create_dir_all(&out_dir)
        .map_err(|e| format!("cannot create {}: {e}", out_dir.display()))?;
    let tmp = out.with_extension("fmu.tmp");
    let file =
        std::fs::File::create(&tmp).map_err(|e| format!("cannot create {}: {e}", tmp.display()))?;
    let mut zip = ZipWriter::new(file);
    let opts = |mode: u32| {
        SimpleFileOptions::default()
            .compression_method(CompressionMethod::Deflated)
            .last_modified_time(DateTime::default())
            .unix_permissions(mode)
    };
    let z = |e: zip::result::ZipError| format!("writing {}: {e}", tmp.display());
    for dir in [
        "binaries/",
        "binaries/linux64/",
        "documentation/",
        "resources/",
    ] {
        zip.add_directory(dir, opts(0o755)).map_err(z)?;
    }
    for (name, data, mode) in entries {
        zip.start_file(name, opts(mode)).map_err(z)?;
        zip.write_all(data)
            .map_err(|e| format!("writing {}: {e}", tmp.display()))?;
    }
    zip.finish().map_err(z)?;
    std::fs::rename(&tmp, out)
        .map_err(|e| format!("cannot move {} to {}: {e}", tmp.display(), out.display()))
}

pub(crate) fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// One HTML table of every variable of modelDescription.xml.
fn variable_table(xml: &str) -> Res<String> {
    let doc = roxmltree::Document::parse(xml).map_err(|e| format!("modelDescription.xml: {e}"))?;
    let mut enums = std::collections::HashMap::new();
    for st in doc.descendants().filter(|n| n.has_tag_name("SimpleType")) {
        let items: Vec<String> = st
            .descendants()
            .filter(|n| n.has_tag_name("Item"))
            .map(|i| {
                format!(
                    "{} = {}",
                    i.attribute("value").unwrap_or("?"),
                    i.attribute("name").unwrap_or("?")
                )
            })
            .collect();
        enums.insert(
            st.attribute("name").unwrap_or("").to_string(),
            items.join(", "),
        );
    }
    let mut rows = String::new();
    for causality in ["input", "output", "parameter"] {
        rows.push_str(&format!("<h3>{causality}s</h3>\n<table>\n<tr><th>name</th><th>type</th><th>unit</th><th>start / default</th><th>range</th><th>description</th></tr>\n"));
        for sv in doc
            .descendants()
            .filter(|n| n.has_tag_name("ScalarVariable"))
        {
            if sv.attribute("causality").unwrap_or("local") != causality {
                continue;
            }
            let ty = sv
                .children()
                .find(|n| n.is_element())
                .ok_or("a variable without a type")?;
            let mut type_name = ty.tag_name().name().to_string();
            if let Some(t) = ty.attribute("declaredType") {
                type_name = format!(
                    "{type_name} {t} ({})",
                    enums.get(t).cloned().unwrap_or_default()
                );
            }
            let unit = match (ty.attribute("unit"), ty.attribute("displayUnit")) {
                (Some(u), Some(d)) => format!("{u} (display {d})"),
                (Some(u), None) => u.to_string(),
                _ => String::new(),
            };
            let start = match ty.attribute("start") {
                Some("") => "\"\"".to_string(),
                Some(s) => s.to_string(),
                None => "(calculated)".to_string(),
            };
            let range = match (ty.attribute("min"), ty.attribute("max")) {
                (None, None) => String::new(),
                (lo, hi) => format!("[{}, {}]", lo.unwrap_or("-inf"), hi.unwrap_or("inf")),
            };
            rows.push_str(&format!(
                "<tr><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                escape(sv.attribute("name").unwrap_or("")),
                escape(&type_name),
                escape(&unit),
                escape(&start),
                escape(&range),
                escape(sv.attribute("description").unwrap_or("")),
            ));
        }
        rows.push_str("</table>\n");
    }
    Ok(rows)
}
