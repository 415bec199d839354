"""Radiosity for a moving light with reuse of paths, as a VTK filter.

    from movinglightradiosity import vtkMovingLightRadiosity, vtkRadiositySceneReader, vtkSunPathSource

The wrapped module sits next to ParaView's ``vtkmodules`` and imports the VTK modules it
derives from on its own, so this works from plain Python, pvpython and pvbatch alike.
"""
from .MovingLightRadiosityFilters import (
    vtkMovingLightRadiosity,
    vtkRadiositySceneReader,
    vtkSunPathSource,
)

__all__ = ["vtkMovingLightRadiosity", "vtkRadiositySceneReader", "vtkSunPathSource"]
