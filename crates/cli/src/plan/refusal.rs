//! Why a task is refused at its start, and what would change it: the constraint that blocks
//! every start the planner can try, never the planner or seed already in use.

use std::path::Path;

use emg_control::{Task, Violation, WORK_SURFACE};
use emg_kinematics::Robot;
use emg_planner::{PlanRequest, Planner, PlannerKind, StartBlockers};

/// At most this many blocking contacts are listed.
const LISTED_CONTACTS: usize = 3;

/// The refusal of `task`, whose start breaks `violation` (the planned start's), or for which no
/// start could be prepared at all (`None`). The search tried every start it has, so its
/// refusal names what blocks every configuration at `p0` ([`Planner::start_blockers`]); the
/// pipeline's names the violation of its one start and the search.
pub fn refusal(
    planner: &Planner,
    robot_file: &Path,
    request: &PlanRequest,
    task: &Task,
    violation: Option<&Violation>,
) -> String {
    let robot = planner.robot();
    if request.planner == PlannerKind::Controller
        && let Some(violation) = violation
    {
        let fixed = fixed_contact_hint(robot, violation);
        let advice = if fixed.is_empty() {
            "; --planner search (the default) tries other starts"
        } else {
            ""
        };
        return format!("the start configuration breaks a constraint: {violation}{fixed}{advice}");
    }
    let why = if task.inside_base_column() {
        "p0 lies inside the space the arm's base occupies (its base link and first body, turned \
         about the first joint), where no part can be; move the part away from the base"
            .to_string()
    } else {
        let theta = planner.config().rollout.constraints.theta_max_deg;
        blockers_text(robot, robot_file, &planner.start_blockers(task), theta)
    };
    format!("no configuration at p0 holds every constraint: {why}")
}

/// What the configurations at `p0` break, and what would change it.
fn blockers_text(
    robot: &Robot,
    robot_file: &Path,
    blockers: &StartBlockers,
    theta_max_deg: f64,
) -> String {
    let Some(first) = blockers.contacts.first() else {
        return format!(
            "none of {} inverse-kinematics restarts puts the TCP at p0 with the tool within \
             {theta_max_deg}° of n and every joint within its limits; move the part nearer the \
             arm's mid-reach, tilt n, or widen the cone (rollout.constraints.theta_max_deg)",
            blockers.restarts,
        );
    };
    let listed: Vec<String> = blockers
        .contacts
        .iter()
        .take(LISTED_CONTACTS)
        .map(|contact| format!("{} of them: {}", contact.count, contact.violation))
        .collect();
    format!(
        "of the {} configurations found at p0 with the tool in its cone and the joints in their \
         limits ({} inverse-kinematics restarts), {}{}",
        blockers.found,
        blockers.restarts,
        listed.join("; "),
        advice(robot, robot_file, &first.violation)
    )
}

/// What would clear `violation`, the contact that blocks the most starts.
fn advice(robot: &Robot, robot_file: &Path, violation: &Violation) -> String {
    let fixed = fixed_contact_hint(robot, violation);
    if !fixed.is_empty() {
        return fixed;
    }
    match violation {
        Violation::SceneContact { obstacle, .. } if obstacle == WORK_SURFACE => {
            "; give the part's real size (rollout.constraints.work_surface in --config), tilt n, \
             or move the part"
                .to_string()
        }
        Violation::SceneContact { obstacle, .. } => {
            format!("; move the part or the scene's {obstacle}")
        }
        Violation::SelfCollision {
            first_link,
            second_link,
            clearance_m,
        } if !crate::robot::is_shipped(robot_file) => format!(
            "; the arm's links are checked as the capsules fitted to their collision geometry, \
             and the capsules of {first_link} and {second_link} overlap by {:.2} mm there \
             while the vendor's meshes may be clear: `emg import-robot --max-capsules 3` fits \
             tighter capsules, and an SRDF's disable_collisions pair (`--srdf`) stops checking \
             two links that never touch",
            -clearance_m * 1e3
        ),
        _ => "; move the part, or tilt n".to_string(),
    }
}

/// Why no plan can start, when `violation` is a contact of a link that never moves (its
/// capsules ride on the base): no configuration clears it, so the cell must change.
fn fixed_contact_hint(robot: &Robot, violation: &Violation) -> String {
    let Violation::SceneContact { link, obstacle, .. } = violation else {
        return String::new();
    };
    let fixed = robot
        .capsules()
        .iter()
        .filter(|c| &c.link == link)
        .all(|c| c.segment == 0);
    if !fixed {
        return String::new();
    }
    let option = if obstacle == WORK_SURFACE {
        ", give the part's size (rollout.constraints.work_surface in --config), or plan with \
         --surface off"
    } else {
        ""
    };
    format!(
        "; the {obstacle} cuts {link}, which never moves: no configuration clears it; move the \
         part or the base{option}"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fr3() -> Robot {
        crate::robot::load_robot(&crate::robot::default_robot(), None, None).unwrap()
    }

    #[test]
    fn an_imported_arms_self_collision_is_said_to_be_its_capsules() {
        let robot = fr3();
        let overlap = Violation::SelfCollision {
            first_link: "shoulder_link".into(),
            second_link: "forearm_link".into(),
            clearance_m: -0.01175,
        };
        let imported = advice(&robot, Path::new("imported/ur10.urdf"), &overlap);
        assert!(
            imported.contains("capsules of shoulder_link and forearm_link overlap by 11.75 mm")
                && imported.contains("--max-capsules")
                && imported.contains("meshes may be clear"),
            "{imported}"
        );
        let shipped = advice(&robot, &crate::robot::default_robot(), &overlap);
        assert!(!shipped.contains("capsules"), "{shipped}");
        for text in [imported, shipped] {
            assert!(
                !text.contains("--seed") && !text.contains("--planner"),
                "{text}"
            );
        }
    }

    #[test]
    fn a_contact_of_a_link_that_never_moves_asks_for_the_cell_to_change() {
        let robot = fr3();
        let fixed = robot.capsules().iter().find(|c| c.segment == 0).unwrap();
        let contact = Violation::SceneContact {
            link: fixed.link.clone(),
            obstacle: WORK_SURFACE.into(),
            clearance_m: -0.01,
        };
        let text = advice(&robot, &crate::robot::default_robot(), &contact);
        assert!(
            text.contains("which never moves") && text.contains("--surface off"),
            "{text}"
        );
    }
}
