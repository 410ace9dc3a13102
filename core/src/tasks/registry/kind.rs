//! The models and the tasks flown on them, with the names front ends use for them.

/// The simulated vehicle model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelKind {
    Quadrotor,
    Lander2d,
}

impl ModelKind {
    /// Every model, in the order front ends list them.
    pub const ALL: [ModelKind; 2] = [ModelKind::Quadrotor, ModelKind::Lander2d];

    /// The model's name (the SITL's `--model`).
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Quadrotor => "quadrotor",
            ModelKind::Lander2d => "lander2d",
        }
    }

    /// The model called `name`.
    pub fn from_name(name: &str) -> Option<ModelKind> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// The task flown on the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TaskKind {
    Hover,
    Waypoints,
    Landing,
}

impl TaskKind {
    /// Every task, in the order front ends list them.
    pub const ALL: [TaskKind; 3] = [TaskKind::Hover, TaskKind::Waypoints, TaskKind::Landing];

    /// The model a task runs on.
    pub fn model(self) -> ModelKind {
        match self {
            TaskKind::Hover | TaskKind::Waypoints => ModelKind::Quadrotor,
            TaskKind::Landing => ModelKind::Lander2d,
        }
    }

    /// The default task of a model.
    pub fn default_for(model: ModelKind) -> TaskKind {
        match model {
            ModelKind::Quadrotor => TaskKind::Hover,
            ModelKind::Lander2d => TaskKind::Landing,
        }
    }

    /// The task's name (the SITL's `--task` and its task frame's name, so at most 10
    /// characters).
    pub fn frame_name(self) -> &'static str {
        match self {
            TaskKind::Hover => "hover",
            TaskKind::Waypoints => "waypoints",
            TaskKind::Landing => "landing",
        }
    }

    /// The task called `name`.
    pub fn from_name(name: &str) -> Option<TaskKind> {
        Self::ALL.into_iter().find(|t| t.frame_name() == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_fit_the_frame() {
        for task in TaskKind::ALL {
            assert_eq!(TaskKind::from_name(task.frame_name()), Some(task));
            assert!(task.frame_name().len() <= 10);
            assert_eq!(TaskKind::default_for(task.model()).model(), task.model());
        }
        for model in ModelKind::ALL {
            assert_eq!(ModelKind::from_name(model.name()), Some(model));
        }
        assert_eq!(TaskKind::from_name("hovering"), None);
    }
}
