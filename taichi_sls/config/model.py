"""The base of every case table: strict types, no unknown keys, no infinities."""

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field


class Model(BaseModel):
    """Strict: an integer is a number, but a string or a boolean is neither; unknown keys are
    errors; infinities and NaN are refused."""

    model_config = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False)


# an [x, y] pair as TOML writes it (a list)
Pair = Annotated[list[float], Field(min_length=2, max_length=2)]
