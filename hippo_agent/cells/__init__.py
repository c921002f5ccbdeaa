"""The paper's four cell types, one module each (paper section "Model Description")."""

from hippo_agent.cells.boundary_vector import BoundaryVectorCells
from hippo_agent.cells.head_direction import HeadDirectionCells
from hippo_agent.cells.place import PlaceCells
from hippo_agent.cells.reward import RewardCells, replay

__all__ = ["BoundaryVectorCells", "HeadDirectionCells", "PlaceCells", "RewardCells", "replay"]
