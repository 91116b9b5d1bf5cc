"""The criteria's engine side under the name yadebreak.coupling.criteria forwards to (see
_moved.py): each criterion is one class of yadebreak.criteria holding both sides."""
from yadebreak.criteria import (AbT10, Judgement, Recording, Tavares, criterion_for,  # noqa: F401
                                judge_all)
