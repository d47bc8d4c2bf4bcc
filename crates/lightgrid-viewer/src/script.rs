//! Scripted sessions (`lightgrid view --script`): steps run at displayed-frame numbers, so a
//! test or a demo can switch pipelines, resize the window, change the view and take
//! screenshots without a person at the keyboard.
//!
//! Syntax: steps separated by `;`, each `at N ACTION` (N: the displayed frame, from 0 to
//! [`MAX_AT`]) or a bare `ACTION` (frame 0); the steps due at one frame run together in that
//! frame, up to a screenshot or a resize (which wait for the frame to show them). Actions:
//! `pipeline ID`, `tile N`, `msaa N`, `view shaded|lights|bounds|wasted`, `resize WxH`
//! (each edge 1 to [`MAX_RESIZE_EDGE`]),
//! `frame F` (jump the animation), `pause`, `play`, `panel on|off`, `screenshot FILE.png`,
//! and the scene's options (the scene is opened again): `spots F` (the spot fraction, 0 to
//! 1), `transparency on|off`, `add-lights N` (N scattered lights; 0 removes them).

use lightgrid::debug_view::DebugView;
use std::path::PathBuf;

#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    Pipeline(String),
    Tile(u32),
    /// A row of the settings table (`lightgrid::pipelines::AXES`): its flag and the value's
    /// name (`msaa 4`, `brdf ggx`, `shadows maps`, `depth-mask on`, ...), checked by the row.
    Setting(&'static str, String),
    View(DebugView),
    Resize(u32, u32),
    Frame(u32),
    Pause,
    Play,
    Panel(bool),
    Screenshot(PathBuf),
    Spots(f32),
    Transparency(bool),
    AddLights(u32),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    pub at: u32,
    pub action: Action,
}

/// Latest settled frame a step may be due at: 17 seconds at 60 frames per second, a few
/// minutes at a software adapter's rate, and more than any test or demo here waits;
/// `at 4294967295` would never end.
pub const MAX_AT: u32 = 1_000;

/// Largest window edge `resize` asks for: a 4K display's width and more (a larger window
/// than any screen shows would render for minutes a frame on a software adapter).
pub const MAX_RESIZE_EDGE: u32 = 4096;

fn number(word: Option<&str>, what: &str, step: &str) -> Result<u32, String> {
    let w = word.ok_or_else(|| format!("'{step}': {what} needs a number"))?;
    w.parse::<u32>()
        .map_err(|_| format!("'{step}': '{w}' is not a whole number ({what})"))
}

/// A settings-table step, its value checked by the row's own `set` (the values and ranges
/// the options accept).
fn setting(
    axis: &'static lightgrid::pipelines::Axis,
    value: Option<&str>,
    step: &str,
) -> Result<Action, String> {
    let names: Vec<&str> = (axis.values)().iter().map(|v| v.name).collect();
    let expected = if names.is_empty() {
        "a number".to_string()
    } else {
        names.join(", ")
    };
    let value = value.ok_or_else(|| format!("'{step}': {} needs {expected}", axis.flag))?;
    (axis.set)(&mut lightgrid::RenderSettings::default(), value)
        .map_err(|e| format!("'{step}': {e}"))?;
    Ok(Action::Setting(axis.flag, value.to_string()))
}

/// Parse a script; steps come back in frame order (steps of one frame in their written order).
pub fn parse(script: &str) -> Result<Vec<Step>, String> {
    let mut steps = Vec::new();
    for raw in script.split(';') {
        let step = raw.trim();
        if step.is_empty() {
            continue;
        }
        let mut words = step.split_whitespace().peekable();
        let mut at = 0;
        if words.peek() == Some(&"at") {
            words.next();
            at = number(words.next(), "at", step)?;
            if at > MAX_AT {
                return Err(format!(
                    "'{step}': at most 'at {MAX_AT}' (settled frames shown; a later step would keep the window open for hours)"
                ));
            }
        }
        let verb = words
            .next()
            .ok_or_else(|| format!("'{step}': an action is missing after 'at {at}'"))?;
        let arg = words.next();
        let action = match verb {
            "pipeline" => Action::Pipeline(
                arg.ok_or_else(|| format!("'{step}': pipeline needs an id"))?
                    .to_string(),
            ),
            "tile" => Action::Tile(number(arg, "tile", step)?),
            "view" => Action::View(arg.and_then(DebugView::parse).ok_or_else(|| {
                format!("'{step}': view is one of shaded, lights, bounds, wasted")
            })?),
            "resize" => {
                let a = arg.ok_or_else(|| format!("'{step}': resize needs WIDTHxHEIGHT"))?;
                let (w, h) = a
                    .split_once(['x', 'X'])
                    .ok_or_else(|| format!("'{step}': '{a}' is not WIDTHxHEIGHT"))?;
                let w = number(Some(w), "resize width", step)?;
                let h = number(Some(h), "resize height", step)?;
                if w == 0 || h == 0 {
                    return Err(format!(
                        "'{step}': both edges must be 1 to {MAX_RESIZE_EDGE}"
                    ));
                }
                if w > MAX_RESIZE_EDGE || h > MAX_RESIZE_EDGE {
                    return Err(format!(
                        "'{step}': both edges must be 1 to {MAX_RESIZE_EDGE}"
                    ));
                }
                Action::Resize(w, h)
            }
            "frame" => Action::Frame(number(arg, "frame", step)?),
            "spots" => {
                let a = arg.ok_or_else(|| format!("'{step}': spots needs a fraction"))?;
                match a.parse::<f32>() {
                    Ok(f) if (0.0..=1.0).contains(&f) => Action::Spots(f),
                    _ => return Err(format!("'{step}': '{a}' is not a number from 0 to 1")),
                }
            }
            "transparency" => match arg {
                Some("on") => Action::Transparency(true),
                Some("off") => Action::Transparency(false),
                _ => return Err(format!("'{step}': transparency is on or off")),
            },
            "add-lights" => {
                let n = number(arg, "add-lights", step)?;
                if n > lightgrid::consts::MAX_LIGHTS {
                    return Err(format!(
                        "'{step}': at most {} lights",
                        lightgrid::consts::MAX_LIGHTS
                    ));
                }
                Action::AddLights(n)
            }
            "pause" => Action::Pause,
            "play" => Action::Play,
            "panel" => match arg {
                Some("on") => Action::Panel(true),
                Some("off") => Action::Panel(false),
                _ => return Err(format!("'{step}': panel is on or off")),
            },
            "screenshot" => {
                let p = arg.ok_or_else(|| format!("'{step}': screenshot needs a file"))?;
                Action::Screenshot(PathBuf::from(p))
            }
            other => match lightgrid::pipelines::find_axis(other) {
                Some(axis) => setting(axis, arg, step)?,
                None => return Err(format!("'{step}': unknown action '{other}'")),
            },
        };
        let takes_arg = !matches!(action, Action::Pause | Action::Play);
        if words.next().is_some() || (!takes_arg && arg.is_some()) {
            return Err(format!("'{step}': too many words"));
        }
        steps.push(Step { at, action });
    }
    steps.sort_by_key(|s| s.at);
    Ok(steps)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_action_in_frame_order() {
        let s = parse(
            "frame 40; pause; at 9 view heatmap; at 3 pipeline tiled_deferred; at 6 resize 300x200; at 9 screenshot a.png; at 12 panel off; tile 32; msaa 4; play",
        )
        .unwrap();
        let at: Vec<u32> = s.iter().map(|s| s.at).collect();
        assert_eq!(at, vec![0, 0, 0, 0, 0, 3, 6, 9, 9, 12]);
        assert_eq!(s[0].action, Action::Frame(40));
        assert_eq!(s[5].action, Action::Pipeline("tiled_deferred".into()));
        assert_eq!(s[6].action, Action::Resize(300, 200));
        assert_eq!(s[7].action, Action::View(DebugView::LightsPerCell));
        assert_eq!(s[8].action, Action::Screenshot("a.png".into()));
        assert_eq!(s[9].action, Action::Panel(false));
        let s = parse("spots 0.25; transparency off; add-lights 0; add-lights 300").unwrap();
        let actions: Vec<Action> = s.into_iter().map(|s| s.action).collect();
        assert_eq!(
            actions,
            vec![
                Action::Spots(0.25),
                Action::Transparency(false),
                Action::AddLights(0),
                Action::AddLights(300)
            ]
        );
        // Every row of the settings table is a step, with its default value.
        for axis in lightgrid::pipelines::AXES {
            let value = (axis.get)(&lightgrid::RenderSettings::default());
            let s = parse(&format!("{} {value}", axis.flag)).unwrap();
            assert_eq!(s[0].action, Action::Setting(axis.flag, value));
        }
        let s = parse("brdf ggx; shadows maps; depth-mask on").unwrap();
        assert_eq!(s[0].action, Action::Setting("brdf", "ggx".into()));
        assert_eq!(s[2].action, Action::Setting("depth-mask", "on".into()));
    }

    #[test]
    fn refuses_what_it_cannot_run() {
        for bad in [
            "at",
            "at x pause",
            "at 3",
            "fly away",
            "tile",
            "brdf",
            "brdf lambert",
            "shadows",
            "shadows soft",
            "msaa",
            "msaa 3",
            "slices 0",
            "depth-mask maybe",
            "assign",
            "tile -4",
            "tile NaN",
            "resize 300",
            "resize 0x",
            "resize 0x10",
            "resize 99999x10",
            "view sideways",
            "panel maybe",
            "pause now",
            "pipeline",
            "screenshot",
            "frame 1 2",
            "spots",
            "spots NaN",
            "spots -0.5",
            "spots 1.5",
            "transparency maybe",
            "add-lights -1",
            "add-lights 99999999",
            "at 1001 pause",
            "resize 4097x10",
            "resize 16384x16384",
            "at 4294967295 pause",
        ] {
            assert!(parse(bad).is_err(), "{bad} parsed");
        }
        assert_eq!(parse(" ; ;").unwrap(), vec![]);
        assert_eq!(parse(&format!("at {MAX_AT} pause")).unwrap()[0].at, MAX_AT);
        let edge = format!("resize {MAX_RESIZE_EDGE}x{MAX_RESIZE_EDGE}");
        assert_eq!(
            parse(&edge).unwrap()[0].action,
            Action::Resize(MAX_RESIZE_EDGE, MAX_RESIZE_EDGE)
        );
    }
}
