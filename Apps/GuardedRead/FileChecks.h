// Checks of input files made before VTK's readers see them: some files crash or mislead
// those readers (found by fuzzing, see Testing/Fuzz), and a crash in the command line or in
// ParaView loses work. Each check reads the file itself, cheaply, and throws InputError
// naming the problem; a file that passes is handed to VTK as before.
#pragma once

#include <string>

namespace mlr::guarded
{

/**
 * Wavefront OBJ: every index of an f, l or p statement must name a vertex (v), texture
 * coordinate (vt) or normal (vn) that the file defines; VTK 9.2's vtkOBJReader reads past its
 * arrays (and crashes on texture coordinates the file does not have) otherwise.
 * `what` names the file in messages ("the scene file 'x.obj'").
 */
void checkObjFile(const std::string& path, const std::string& what);

/**
 * STL: a binary file (any that is not plain ASCII text starting with "solid") must hold the
 * triangles its header counts: vtkSTLReader allocates for the count first, so a damaged count
 * asks for gigabytes.
 */
void checkStlFile(const std::string& path, const std::string& what);

/**
 * PLY: the header must be complete (ply, format, end_header) and declare a vertex element
 * with x, y and z, with property types PLY knows, and element counts the rest of the file
 * can hold; vtkPLYReader crashes on headers without the elements it looks for.
 */
void checkPlyFile(const std::string& path, const std::string& what);

} // namespace mlr::guarded
