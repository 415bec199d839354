# find_package(MovingLightRadiosity) gives the VTK module MovingLightRadiosity::Filters
# (vtkMovingLightRadiosity, vtkRadiositySceneReader, vtkSunPathSource), built against
# ParaView 5.11's VTK, which this finds too. Core and Embree are inside its library.
include(CMakeFindDependencyMacro)
find_dependency(ParaView 5.11 COMPONENTS RemotingCore)
find_dependency(VTK COMPONENTS CommonCore CommonDataModel CommonExecutionModel)
include("${CMAKE_CURRENT_LIST_DIR}/MovingLightRadiosity-targets.cmake")
include("${CMAKE_CURRENT_LIST_DIR}/MovingLightRadiosity-vtk-module-properties.cmake")
