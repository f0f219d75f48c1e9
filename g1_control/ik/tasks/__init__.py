"""IK tasks: each a cost the QP trades off against the others."""

from g1_control.ik.tasks.base import Task
from g1_control.ik.tasks.com_task import ComTask
from g1_control.ik.tasks.damping_task import DampingTask
from g1_control.ik.tasks.frame_task import FrameTask, pose_from_vector
from g1_control.ik.tasks.posture_task import PostureTask
from g1_control.ik.tasks.relative_frame_task import RelativeFrameTask
from g1_control.ik.tasks.smoothness_task import SmoothnessTask

__all__ = [
           "ComTask",
           "DampingTask",
           "FrameTask",
           "PostureTask",
           "RelativeFrameTask",
           "SmoothnessTask",
           "Task",
           "pose_from_vector",
]
