"""The public face of softhand.studies: what examples and users import."""
from . import bending, reservoir, weights
from .batch.runner import index_rows, run_study
from .batch.studyfile import study_from_dict
from .bending import BendingStudy
