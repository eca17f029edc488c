"""The base of every case table: strict types, no unknown keys, no infinities."""

from typing import Annotated

from pydantic import AfterValidator, BaseModel, ConfigDict, Field


class Model(BaseModel):
    """Strict: an integer is a number, but a string or a boolean is neither; unknown keys are
    errors; infinities and NaN are refused."""

    model_config = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False)


# an [x, y] pair as TOML writes it (a list)
Pair = Annotated[list[float], Field(min_length=2, max_length=2)]


def _two_or_three(v: list[float]) -> list[float]:
    if len(v) not in (2, 3):
        raise ValueError("expected [x, y] (2D) or [x, y, z] (3D)")
    return v


# a position or vector: [x, y] in 2D, [x, y, z] in 3D (the case checks the count against domain.dim)
Point = Annotated[list[float], AfterValidator(_two_or_three)]
