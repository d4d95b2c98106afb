#pragma once
/// \file case_fingerprint.h
/// What a segmentation was made from, by content: the image's bytes, the model's manifest and
/// the options, each as FNV-1a 64 in hex, and mrsnake's version. report.json keeps it under
/// "fingerprint"; `segment-batch --resume` keeps an earlier result only while it is the same.
#include <string>

#include <nlohmann/json.hpp>

namespace mrsnake::cli {

struct CaseFingerprint {
  std::string image, model, options, version;
  /// False when the image's data files could not all be hashed: no earlier result counts as its.
  bool comparable() const { return image.rfind("unfollowed", 0) != 0; }
  bool operator==(const CaseFingerprint& other) const {
    return image == other.image && model == other.model && options == other.options && version == other.version;
  }
};

/// The hash of the DICOM `series` chosen (empty for none) and of an image file's bytes; of a
/// header (.mhd, .nhdr, .hdr) and the data file it names; or of a DICOM folder's files, names
/// and bytes, in name order. A header whose data files cannot be followed (a list, a pattern)
/// gets a fingerprint no result holds, so that its image is always segmented again.
/// \throw InputError if a file cannot be read or the folder listed.
std::string image_fingerprint(const std::string& path, const std::string& series = "");

/// The hash of the model folder's model.json, which lists every part with its own checksum
/// (a model of many structures lists each structure's manifest checksum), so that it changes
/// with any part; loading the model checks the parts against it.
/// \throw InputError if model.json cannot be read.
std::string model_fingerprint(const std::string& folder);

/// The hash of the options' compact JSON text.
std::string options_fingerprint(const nlohmann::json& options);

void to_json(nlohmann::json& j, const CaseFingerprint& f);
/// A fingerprint with every field empty when `j` is not one (an older report).
CaseFingerprint fingerprint_from_json(const nlohmann::json& j);

}  // namespace mrsnake::cli
