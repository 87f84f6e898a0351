//! The digital output that switches the tool (a pen's actuator, a dispenser's valve, a torch's
//! trigger) on along each stroke and off between strokes, as a job's settings name it.

use serde::{Deserialize, Serialize};

use crate::setting::InvalidSetting;

/// A controller's bank of digital outputs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OutputBank {
    /// The control box's standard outputs (a UR controller's `set_standard_digital_out`, 0–7).
    #[default]
    Standard,
    /// The outputs at the tool flange (a UR controller's `set_tool_digital_out`, 0–1).
    Tool,
}

impl OutputBank {
    /// The bank's name in a job file.
    pub fn name(self) -> &'static str {
        match self {
            Self::Standard => "standard",
            Self::Tool => "tool",
        }
    }

    /// The highest output number of the bank.
    pub fn last_output(self) -> u32 {
        match self {
            Self::Standard => 7,
            Self::Tool => 1,
        }
    }
}

/// Which output switches the tool, at which level, and how long it dwells on at a stroke's
/// ends.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ToolOutput {
    /// The bank of the output.
    pub bank: OutputBank,
    /// The output's number in its bank.
    pub number: u32,
    /// Whether the output high (`true`) or low (`false`) switches the tool on.
    pub on_high: bool,
    /// How long the tool is on at a stroke's start before it moves along it (s): a dispenser's
    /// pre-flow, a torch's arc start.
    pub lead_s: f64,
    /// How long the tool stays on at a stroke's end before it is switched off and lifted (s): a
    /// torch's crater fill.
    pub lag_s: f64,
}

impl Default for ToolOutput {
    fn default() -> Self {
        Self {
            bank: OutputBank::Standard,
            number: 0,
            on_high: true,
            lead_s: 0.0,
            lag_s: 0.0,
        }
    }
}

impl ToolOutput {
    /// The longest dwell at a stroke's end (s).
    pub const MAX_DWELL_S: f64 = 10.0;

    /// Checks the number against its bank and the dwells, naming the field.
    pub fn validate(&self) -> Result<(), InvalidSetting> {
        let last = self.bank.last_output();
        if self.number > last {
            return Err(InvalidSetting {
                field: "tool_output.number",
                value: f64::from(self.number),
                allowed: match self.bank {
                    OutputBank::Standard => "in [0, 7] for the standard outputs",
                    OutputBank::Tool => "in [0, 1] for the tool outputs",
                },
            });
        }
        for (field, value) in [
            ("tool_output.lead_s", self.lead_s),
            ("tool_output.lag_s", self.lag_s),
        ] {
            if !(value.is_finite() && (0.0..=Self::MAX_DWELL_S).contains(&value)) {
                return Err(InvalidSetting {
                    field,
                    value,
                    allowed: "in [0, 10] s",
                });
            }
        }
        Ok(())
    }

    /// The output's level that switches the tool on (`on`) or off.
    pub fn level(&self, on: bool) -> bool {
        on == self.on_high
    }
}

impl std::fmt::Display for ToolOutput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} digital output {}, {} switches it on; lead {} s, lag {} s",
            self.bank.name(),
            self.number,
            if self.on_high { "high" } else { "low" },
            self.lead_s,
            self.lag_s
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_output_past_its_bank_or_a_negative_dwell_is_refused_naming_the_field() {
        assert!(ToolOutput::default().validate().is_ok());
        let tool_two = ToolOutput {
            bank: OutputBank::Tool,
            number: 2,
            ..ToolOutput::default()
        };
        let message = tool_two.validate().unwrap_err().to_string();
        assert!(message.contains("tool_output.number"), "{message}");
        let early = ToolOutput {
            lead_s: -0.1,
            ..ToolOutput::default()
        };
        let message = early.validate().unwrap_err().to_string();
        assert!(message.contains("tool_output.lead_s"), "{message}");
    }

    #[test]
    fn an_output_low_for_on_inverts_the_levels() {
        let low = ToolOutput {
            on_high: false,
            ..ToolOutput::default()
        };
        assert!(!low.level(true) && low.level(false));
        assert!(ToolOutput::default().level(true));
    }
}
