#pragma once
/// \file dicom_series_itk.h
/// A DICOM series written through ITK (GDCM) for the tests: one file per slice, with the
/// position, orientation, spacing and UIDs that a reader needs to put them back together.
#include <string>

#include "mesh/volume.h"

namespace mrsnake::test {

/// Writes `volume` (rounded to int16) as a series of slices `PREFIX_NNN.dcm` into `dir`, with
/// Series Instance UID `series_uid` and Series Description `description`.
/// \throw std::runtime_error if ITK cannot write it.
void write_dicom_series(const std::string& dir, const std::string& prefix, const Volume& volume,
                        const std::string& series_uid, const std::string& description);

}  // namespace mrsnake::test
