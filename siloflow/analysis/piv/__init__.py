"""PIV: measured velocity fields brought into the neutral planar field (:mod:`siloflow.analysis.piv.field`), the image scale
from wall markers (:mod:`siloflow.analysis.piv.calibration`) and outlier removal (:mod:`siloflow.analysis.piv.hampel`). Readers of the
PIV programs' files are at the edge, in :mod:`siloflow.analysis.io.piv`."""
