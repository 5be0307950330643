//! The 2D fields written by `run --fields FILE`: CSV (one row per cell, for pandas) or, for a
//! file named `*.vti`, VTK image data (cell data, for ParaView) through `vtkio`.

use crate::error::{Error, Result};
use crate::measure::fields::Fields;
use std::path::Path;

/// The per-cell quantities, in file order: name and one value per cell (x fastest); `NaN` where
/// a quantity is undefined (a cell no disk was ever seen in has no velocity or temperature).
pub fn columns(f: &Fields) -> Vec<(&'static str, Vec<f64>)> {
    let g = *f.grid();
    let cells = || (0..g.ny).flat_map(move |j| (0..g.nx).map(move |i| (i, j)));
    let per = |q: &dyn Fn(usize, usize) -> f64| cells().map(|(i, j)| q(i, j)).collect();
    let nan2 = |v: Option<[f64; 2]>| v.unwrap_or([f64::NAN; 2]);
    let mut out: Vec<(&'static str, Vec<f64>)> = vec![
        ("number_density", per(&|i, j| f.number_density(i, j))),
        ("packing_fraction", per(&|i, j| f.packing_fraction(i, j))),
        ("velocity_x", per(&|i, j| nan2(f.mean_velocity(i, j))[0])),
        ("velocity_y", per(&|i, j| nan2(f.mean_velocity(i, j))[1])),
        ("temperature_x", per(&|i, j| nan2(f.temperature(i, j))[0])),
        ("temperature_y", per(&|i, j| nan2(f.temperature(i, j))[1])),
    ];
    if f.rough() {
        out.push((
            "temperature_rotational",
            per(&|i, j| f.rotational_temperature(i, j).unwrap_or(f64::NAN)),
        ));
    }
    out
}

/// The fields as CSV: a header, then one row per cell with its indices `i, j` (column, row),
/// its centre `x, y` and the quantities of [`columns`] (`NaN` where undefined).
pub fn to_csv(f: &Fields) -> String {
    let g = *f.grid();
    let cols = columns(f);
    let mut out = String::from("i,j,x,y");
    for (name, _) in &cols {
        out.push(',');
        out.push_str(name);
    }
    out.push('\n');
    for j in 0..g.ny {
        for i in 0..g.nx {
            let [x, y] = g.centre(i, j);
            out.push_str(&format!("{i},{j},{x},{y}"));
            for (_, v) in &cols {
                out.push_str(&format!(",{}", v[g.index(i, j)]));
            }
            out.push('\n');
        }
    }
    out
}

/// The fields as VTK XML image data: `nx × ny` cells from `(0, bottom)` with spacing
/// `(dx, dy)`, each quantity a cell array (velocity as one 3-component vector).
pub fn to_vti(f: &Fields) -> Result<String> {
    use vtkio::model::{
        Attribute, Attributes, ByteOrder, DataSet, Extent, ImageDataPiece, Piece, Version, Vtk,
    };
    let g = *f.grid();
    let [dx, dy] = g.cell();
    let extent = Extent::Ranges([0..=g.nx as i32, 0..=g.ny as i32, 0..=0]);
    let mut cell = Vec::new();
    let cols = columns(f);
    for (name, v) in &cols {
        if name.starts_with("velocity") {
            continue;
        }
        cell.push(Attribute::scalars(*name, 1).with_data(v.clone()));
    }
    let (ux, uy) = (&cols[2].1, &cols[3].1);
    let velocity: Vec<f64> = (0..g.len()).flat_map(|k| [ux[k], uy[k], 0.0]).collect();
    cell.push(Attribute::vectors("velocity").with_data(velocity));
    let vtk = Vtk {
        version: Version::Auto,
        title: String::new(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::ImageData {
            extent: extent.clone(),
            origin: [0.0, g.bottom as f32, 0.0],
            spacing: [dx as f32, dy as f32, 1.0],
            meta: None,
            pieces: vec![Piece::Inline(Box::new(ImageDataPiece {
                extent,
                data: Attributes {
                    point: Vec::new(),
                    cell,
                },
            }))],
        },
    };
    let mut bytes = Vec::new();
    vtk.write_xml(&mut bytes)
        .map_err(|e| Error::Runtime(format!("cannot encode them as VTK: {e}")))?;
    String::from_utf8(bytes).map_err(|e| Error::Runtime(format!("their VTK is not text: {e}")))
}

/// `true` when `path` asks for VTK image data (named `*.vti`).
pub fn wants_vti(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vti"))
}

/// Writes the fields to `path` (atomically), as VTK image data for `*.vti`, else as CSV; a
/// failure, to encode or to write, names the fields and the file.
pub fn write(path: &Path, f: &Fields) -> Result<()> {
    let text = if wants_vti(path) {
        to_vti(f).map_err(|e| match e {
            Error::Runtime(why) => super::cannot_write("fields", path, why),
            other => other,
        })?
    } else {
        to_csv(f)
    };
    super::write_output("fields", path, &text)
}
