"""A scenario: contacts over time, as :class:`Step` s of contacts held for a duration."""

from __future__ import annotations

from dataclasses import dataclass, field

from tactsense._validation import TactsenseInputError, check_positive
from tactsense.physics.contact import contact_from_dict


@dataclass(frozen=True)
class Step:
    """Contacts held for a duration.

    Parameters
    ----------
    contacts : tuple of contacts
        What touches the skin during the step; empty for nothing.
    duration_s : float
        [s].
    label : str
        Free text stored with the recording.
    """

    contacts: tuple = ()
    duration_s: float = 1.0
    label: str = ""

    def __post_init__(self) -> None:
        check_positive(self.duration_s, "step duration_s")
        object.__setattr__(self, "contacts", tuple(self.contacts))


@dataclass(frozen=True)
class Scenario:
    """A time line of steps, with a name and a description for the recording."""

    steps: tuple[Step, ...]
    name: str = "custom"
    description: str = ""
    parameters: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not self.steps:
            raise TactsenseInputError("a scenario needs at least one step")
        object.__setattr__(self, "steps", tuple(self.steps))

    @property
    def duration_s(self) -> float:
        """Total duration [s]."""
        return float(sum(step.duration_s for step in self.steps))

    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "description": self.description,
            "parameters": self.parameters,
            "steps": [
                {
                    "duration_s": s.duration_s,
                    "label": s.label,
                    "contacts": [c.to_dict() for c in s.contacts],
                }
                for s in self.steps
            ],
        }

    @classmethod
    def from_dict(cls, data: dict) -> Scenario:
        try:
            steps = tuple(
                Step(
                    tuple(contact_from_dict(c) for c in s["contacts"]),
                    s["duration_s"],
                    s.get("label", ""),
                )
                for s in data["steps"]
            )
        except (KeyError, TypeError) as error:
            raise TactsenseInputError(f"malformed scenario description: {error}") from None
        return cls(
            steps,
            data.get("name", "custom"),
            data.get("description", ""),
            data.get("parameters", {}),
        )
