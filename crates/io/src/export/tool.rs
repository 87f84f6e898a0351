//! The tool switched on and off along an exported motion.

/// The tool switched on and off along a motion.
#[derive(Clone, Copy, Debug)]
pub struct ToolSwitching<'a> {
    /// Each switch in time order.
    pub switches: &'a [ToolSwitch],
    /// The output that switches the tool, in words.
    pub output: &'a str,
}

/// The tool switched on or off at a time of the motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToolSwitch {
    /// Time since the motion's start (s).
    pub time_s: f64,
    /// Whether the tool is switched on (else off).
    pub on: bool,
}
