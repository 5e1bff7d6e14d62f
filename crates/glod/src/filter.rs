//! A scene at one GLoD: the shell, the objects of that level and below, and exactly the
//! modifiers they still use.
//!
//! The output is a subset of the input's primitives in input order (modifiers are defined
//! before use, so input order stays valid), each written unchanged. Kept with a surface: its
//! modifier chain (patterns, textures, mixtures up to `void`), for an `alias` the aliased
//! object, and for a kept modifier every earlier modifier named among its string arguments
//! (a `mixfunc`'s two modifiers, `mirror`/`illum` alternates), transitively.

use rdaylight_base::{Error, Result};
use rdaylight_formats::scene::{Alias, Scene};

use crate::level::MAX_LEVEL;
use crate::objects::Analysis;

/// Indices (ascending) of the input objects a level keeps.
pub fn kept(scene: &Scene, analysis: &Analysis, level: u8) -> Vec<usize> {
    let n = scene.objects.len();
    let mut keep = vec![false; n];
    let mut work: Vec<usize> = analysis.shell.clone();
    for o in analysis.objects.iter().filter(|o| o.level <= level) {
        work.extend(&o.members);
    }
    while let Some(i) = work.pop() {
        if i >= n || keep[i] {
            continue;
        }
        keep[i] = true;
        let o = &scene.objects[i];
        if let Some(m) = o.modifier {
            work.push(m);
        }
        if let Some(a) = &o.alias {
            work.push(a.target);
        }
        if o.kind.otype().is_modifier() {
            let (strings, _) = o.kind.to_args();
            for s in strings {
                // The most recent modifier of that name defined before this one.
                if let Some(j) = (0..i).rev().find(|&j| {
                    scene.objects[j].id == s && scene.objects[j].kind.otype().is_modifier()
                }) {
                    work.push(j);
                }
            }
        }
    }
    (0..n).filter(|&i| keep[i]).collect()
}

/// The scene at GLoD `level` (0..=4), with modifier and alias links renumbered.
pub fn filter(scene: &Scene, analysis: &Analysis, level: u8) -> Result<Scene> {
    if level > MAX_LEVEL {
        return Err(Error::Usage(format!(
            "-l {level}: give a level from 0 (shell only) to {MAX_LEVEL} (everything)"
        )));
    }
    let idx = kept(scene, analysis, level);
    let mut new_of = vec![usize::MAX; scene.objects.len()];
    for (k, &i) in idx.iter().enumerate() {
        new_of[i] = k;
    }
    let objects = idx
        .iter()
        .map(|&i| {
            let mut o = scene.objects[i].clone();
            o.modifier = o.modifier.map(|m| new_of[m]);
            o.alias = o.alias.map(|a| Alias {
                target: new_of[a.target],
                target_id: a.target_id,
            });
            o
        })
        .collect();
    // `#@rfluxmtx` lines refer to object positions the filter changed: dropped.
    Ok(Scene {
        objects,
        directives: Vec::new(),
    })
}
