"""Analytic reference solutions used to verify the solver (all SI units).

Each function's docstring names its source and formula. Functions take scalars or numpy arrays
(broadcast) where that is natural; array-valued results are returned as ``float`` for scalar
input and ``numpy.ndarray`` otherwise.

- :mod:`.mechanics`: fixed-free elastic bar, first axial mode; a manufactured large-deformation
  solution of a fixed-fixed bar (Steffen, Kirby & Berzins 2008);
- :mod:`.heat`: erf half-space, spreading 2D Gaussian;
- :mod:`.perzyna`: Perzyna overstress viscoplasticity;
- :mod:`.stefan`: Stefan melting with a linear mushy zone;
- :mod:`.capillarity`: Laplace pressure, viscous and inviscid shape oscillations of a disc and
  of a sphere;
- :mod:`.hopper`: the coalescence of two equal viscous cylinders (Hopper 1984, 1990);
- :mod:`.crystallization`: isothermal Avrami, non-isothermal Nakamura, DSC peak vs cooling rate;
- :mod:`.viscosity`: the Arrhenius law of a melt's zero-shear viscosity.
"""

from .capillarity import *  # noqa: F403
from .crystallization import *  # noqa: F403
from .heat import *  # noqa: F403
from .hopper import *  # noqa: F403
from .mechanics import *  # noqa: F403
from .perzyna import *  # noqa: F403
from .stefan import *  # noqa: F403
from .viscosity import *  # noqa: F403
