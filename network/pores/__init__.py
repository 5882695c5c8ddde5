"""Pores: the Delaunay tessellation, merged pore bodies, the flow sample and its porosity.

:func:`tessellate` makes pores (tetrahedra) and throats (their faces); :func:`merge_pores` and
:func:`tie_groups` join tetrahedra into pore bodies; :func:`default_region`/:func:`select_sample`
cut the interior sample with its inlet and outlet pores; :func:`region_porosity` measures it;
:func:`column_norm` and :func:`cross_components` are the vector helpers of their geometry,
on (3, M) component rows.
"""

from ._merge import PoreMerge, circumspheres, merge_pores
from ..core import OverlapError, region_porosity
from ._region import (AXES, MIN_INTERIOR_DIAMETERS, OUTSIDE_BED_DIAMETERS, NoInteriorError,
                      Region, axis_index, check_inside_bed, default_region, sample_region)
from ._simplex import column_norm, cross_components
from ._sample import (EmptySampleError, SampleNetwork, body_centroids, prune_disconnected,
                      select_sample)
from ._tessellation import QHULL_OPTIONS, Tessellation, tessellate, tie_groups
from ._throat_sample import sample_throats

__all__ = ["AXES", "MIN_INTERIOR_DIAMETERS", "OUTSIDE_BED_DIAMETERS", "QHULL_OPTIONS",
           "PoreMerge", "Region", "SampleNetwork", "Tessellation", "axis_index", "body_centroids",
           "check_inside_bed", "circumspheres", "column_norm", "cross_components",
           "default_region", "merge_pores", "prune_disconnected", "region_porosity", "sample_region", "sample_throats",
           "select_sample", "tessellate", "tie_groups", "EmptySampleError", "NoInteriorError",
           "OverlapError"]
