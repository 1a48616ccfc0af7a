"""PIV: measured velocity fields brought into the neutral planar field (:mod:`analysis.piv.field`), the image scale
from wall markers (:mod:`analysis.piv.calibration`) and outlier removal (:mod:`analysis.piv.hampel`). Readers of the
PIV programs' files are at the edge, in :mod:`analysis.io.piv`."""
