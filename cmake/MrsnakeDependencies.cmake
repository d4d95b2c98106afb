# Third-party packages, all from Debian. Order matters:
# Eigen's config must be found before VTK, whose own FindEigen3 module would shadow it.
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(CGAL REQUIRED)
# SuiteSparse's KLU (libsuitesparse-dev, no CMake config in Debian's 5.12): the sparse LU of the
# mean value parameterization, through Eigen's KLUSupport.
find_path(KLU_INCLUDE_DIR klu.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(KLU_LIBRARY klu REQUIRED)
add_library(SuiteSparse::KLU INTERFACE IMPORTED)
set_target_properties(SuiteSparse::KLU PROPERTIES
  INTERFACE_INCLUDE_DIRECTORIES "${KLU_INCLUDE_DIR}" INTERFACE_LINK_LIBRARIES "${KLU_LIBRARY}")
find_package(VTK REQUIRED COMPONENTS
  CommonCore CommonDataModel CommonExecutionModel CommonTransforms
  FiltersCore FiltersGeneral FiltersModeling FiltersSources FiltersGeometry
  ImagingCore IOGeometry IOLegacy IOPLY IOXML
  RenderingCore RenderingOpenGL2 RenderingAnnotation InteractionStyle IOImage)
# ITK bundles Eigen 3.3 under its include directory. Its include path must never reach a
# translation unit that includes the system Eigen or CGAL, so ITK is only linked PRIVATE
# into the small *_itk targets (see mrsnake_add_itk_library).
find_package(ITK 5.2 REQUIRED COMPONENTS
  ITKCommon ITKIOImageBase ITKIONIFTI ITKIONRRD ITKIOMeta ITKIOGIPL ITKIOGDCM
  ITKImageIntensity ITKImageFilterBase ITKThresholding ITKSmoothing ITKImageGrid
  ITKBinaryMathematicalMorphology ITKLabelMap ITKDistanceMap ITKLevelSets ITKImageGradient ITKRegistrationCommon ITKTransform
  ITKImageFunction ITKStatistics ITKOptimizers ITKImageCompare
  ITKOptimizersv4 ITKMetricsv4 ITKRegistrationMethodsv4)
find_package(CLI11 CONFIG QUIET)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(Threads REQUIRED)
if(MRSNAKE_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
