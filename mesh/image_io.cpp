// ITK translation unit: no Eigen and no CGAL here (ITK bundles its own Eigen).
#include "mesh/image_io.h"

#include <itkGDCMImageIO.h>
#include <itkGDCMImageIOFactory.h>
#include <itkGDCMSeriesFileNames.h>
#include <itkGiplImageIOFactory.h>
#include <itkImage.h>
#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>
#include <itkImageIOFactory.h>
#include <itkImageSeriesReader.h>
#include <itkMetaDataObject.h>
#include <itkMetaImageIOFactory.h>
#include <itkNiftiImageIOFactory.h>
#include <itkNrrdImageIOFactory.h>

#include <zlib.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <vector>
#include <filesystem>
#include <mutex>

#include "mesh/atomic_file.h"
#include "mesh/errors.h"
#include "mesh/parallel.h"

namespace mrsnake {
namespace {

using FloatImage = itk::Image<float, 3>;

// Explicit registration: the project does not use ITK's generated factory-registration
// headers, which need ITK's include path everywhere.
void register_image_io() {
  static std::once_flag once;
  std::call_once(once, [] {
    itk::NiftiImageIOFactory::RegisterOneFactory();
    itk::NrrdImageIOFactory::RegisterOneFactory();
    itk::MetaImageIOFactory::RegisterOneFactory();
    itk::GiplImageIOFactory::RegisterOneFactory();
    itk::GDCMImageIOFactory::RegisterOneFactory();
  });
}

Volume to_volume(const FloatImage* image, const std::string& path) {
  Volume v;
  const auto region = image->GetLargestPossibleRegion();
  for (int d = 0; d < 3; ++d) {
    v.size[d] = region.GetSize()[d];
    v.spacing[d] = image->GetSpacing()[d];
    v.origin[d] = image->GetOrigin()[d];
    for (int c = 0; c < 3; ++c) v.direction[3 * d + c] = image->GetDirection()(d, c);
    if (!(std::isfinite(v.spacing[d]) && v.spacing[d] > 0))
      throw InputError("'" + path + "' has a non-positive or non-finite voxel spacing; fix the image header");
    if (!std::isfinite(v.origin[d])) throw InputError("'" + path + "' has a non-finite origin; fix the image header");
  }
  v.data.assign(image->GetBufferPointer(), image->GetBufferPointer() + v.num_voxels());
  return v;
}

// ITK's readers fill a truncated gzip stream with zeros instead of failing, which would
// turn a damaged scan into a silently wrong segmentation. zlib reports a stream that ends
// early or fails its CRC.
void check_gzip_complete(const std::string& path) {
  std::ifstream probe(path, std::ios::binary);
  unsigned char magic[2] = {0, 0};
  probe.read(reinterpret_cast<char*>(magic), 2);
  if (magic[0] != 0x1f || magic[1] != 0x8b) return;
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) throw InputError("cannot open '" + path + "'");
  std::vector<char> buffer(1 << 20);
  int n = 0;
  while ((n = gzread(f, buffer.data(), static_cast<unsigned>(buffer.size()))) > 0) {
  }
  int err = Z_OK;
  const char* message = gzerror(f, &err);
  const bool complete = n == 0 && err == Z_OK && gzeof(f);
  const std::string why = message ? message : "";
  gzclose(f);
  if (!complete)
    throw InputError("'" + path + "' is truncated or corrupt (" + (why.empty() ? "incomplete gzip stream" : why) +
                     "); re-export or re-copy the file");
}

std::string lower_case(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// The header lines of a MetaImage ("Key = Value", up to ElementDataFile) or NRRD ("key: value",
// up to the first blank line) file, keys lower-cased without spaces.
std::vector<std::pair<std::string, std::string>> header_fields(const std::string& path, char separator) {
  std::vector<std::pair<std::string, std::string>> fields;
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int n = 0; n < 200 && std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) break;  // NRRD: the data follows
    const auto at = line.find(separator);
    if (at == std::string::npos) continue;
    std::string key, value = line.substr(at + 1);
    for (char c : line.substr(0, at))
      if (!std::isspace(static_cast<unsigned char>(c))) key += c;
    key = lower_case(key);
    value.erase(0, value.find_first_not_of(" \t"));
    value.erase(value.find_last_not_of(" \t") + 1);
    fields.emplace_back(key, value);
    if (key == "elementdatafile") break;  // MetaImage: the data follows
  }
  return fields;
}

// Where an image's voxels are: the image file itself (NIfTI, GIPL, a MetaImage or NRRD with
// its data inline) or the data file a .mhd or detached .nhdr names, and whether they are
// stored raw (so that the file must hold all of them). An empty file when they are spread over
// several files or the format is not known here.
struct VoxelFile {
  std::string path;
  bool raw = false;
};

VoxelFile voxel_file(const std::string& path) {
  const std::string extension = lower_case(std::filesystem::path(path).extension().string());
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (extension == ".mha" || extension == ".mhd") {
    std::string data_file;
    bool compressed = false;
    for (const auto& [key, value] : header_fields(path, '=')) {
      // MetaIO reads a value starting with T, t or 1 as true.
      if (key == "compresseddata")
        compressed = !value.empty() && (value[0] == 'T' || value[0] == 't' || value[0] == '1');
      if (key == "elementdatafile") data_file = value;
    }
    // "LIST [2D]" and printf-style patterns spread the voxels over several files.
    if (data_file.empty() || lower_case(data_file).rfind("list", 0) == 0 || data_file.find('%') != std::string::npos)
      return {};
    return {lower_case(data_file) == "local" ? path : (folder / data_file).string(), !compressed};
  }
  if (extension == ".nrrd" || extension == ".nhdr") {
    std::string data_file;
    bool raw = true;
    for (const auto& [key, value] : header_fields(path, ':')) {
      if (key == "encoding") raw = lower_case(value) == "raw";
      if (key == "datafile") data_file = value;
    }
    if (data_file.empty()) return extension == ".nrrd" ? VoxelFile{path, raw} : VoxelFile{};
    if (data_file.find(' ') != std::string::npos || lower_case(data_file).rfind("list", 0) == 0) return {};
    return {(folder / data_file).string(), raw};
  }
  if (extension == ".nii" || extension == ".gipl") return {path, true};
  return {};
}

// An ITK error as one line: without its "ITK ERROR: Class(0x...): " prefix, and with the
// lines of a multi-line reason (teem's NRRD trace) joined, the innermost last.
std::string one_line_itk_error(const std::string& description) {
  std::string out;
  std::size_t start = 0;
  while (start <= description.size()) {
    const std::size_t end = std::min(description.find('\n', start), description.size());
    std::string line = description.substr(start, end - start);
    start = end + 1;
    for (const std::string tag : {"ITK ERROR: ", "itk::ERROR: "})
      if (line.rfind(tag, 0) == 0) {
        line = line.substr(tag.size());
        const auto close = line.find("): ");
        if (line.find('(') != std::string::npos && close != std::string::npos && line.find(' ') > line.find('('))
          line = line.substr(close + 3);  // the "Class(0x...)" token
      }
    while (!line.empty() && (line.back() == ':' || line.back() == ' ' || line.back() == '\r')) line.pop_back();
    while (!line.empty() && line.front() == ' ') line.erase(0, 1);
    if (line.empty()) continue;
    out += (out.empty() ? "" : "; ") + line;
  }
  return out;
}

// A header's separate voxel file must be there (checked before ITK reads the header: its NRRD
// reader fails with a multi-line dump).
void check_voxel_file_exists(const std::string& path, const VoxelFile& voxels) {
  std::error_code ec;
  if (voxels.path.empty() || voxels.path == path) return;
  if (!std::filesystem::exists(voxels.path, ec))
    throw InputError("'" + path + "' names the voxel file '" + voxels.path +
                     "', which is missing; copy it beside the header");
  if (!std::filesystem::is_regular_file(voxels.path, ec))
    throw InputError("'" + path + "' names the voxel file '" + voxels.path + "', which is not a regular file");
}

// Raw voxels must all be there: ITK zero-fills a short file. (Compressed ones are left to
// zlib, which reports a damaged stream itself.)
void check_size(const VoxelFile& voxels, const itk::ImageIOBase* io) {
  if (voxels.path.empty() || !voxels.raw) return;
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(voxels.path, ec);
  if (ec) return;  // not a regular file (a pipe): ITK's reader will tell
  if (bytes < static_cast<std::uintmax_t>(io->GetImageSizeInBytes()))
    throw InputError("'" + voxels.path + "' is truncated: it holds " + std::to_string(bytes) + " bytes for " +
                     std::to_string(io->GetImageSizeInBytes()) + " bytes of voxels");
}

itk::GDCMSeriesFileNames::Pointer series_names(const std::string& dir) {
  auto names = itk::GDCMSeriesFileNames::New();
  names->SetUseSeriesDetails(true);  // series of one UID but other sizes or orientations apart
  names->SetDirectory(dir);
  return names;
}

// Every series of the folder that `names` scanned, each described from its first file's header.
std::vector<DicomSeries> series_of(itk::GDCMSeriesFileNames* names) {
  std::vector<DicomSeries> series;
  for (const std::string& id : names->GetSeriesUIDs()) {
    DicomSeries s;
    s.id = s.uid = id;
    const std::vector<std::string> files = names->GetFileNames(id);
    s.files = files.size();
    try {  // a header that cannot be read leaves the description empty, not the folder unreadable
      auto io = itk::GDCMImageIO::New();
      io->SetFileName(files.front());
      io->ReadImageInformation();
      io->GetValueFromTag("0020|000e", s.uid);
      io->GetValueFromTag("0008|103e", s.description);
    } catch (const itk::ExceptionObject&) {
    }
    for (std::string* text : {&s.uid, &s.description}) text->erase(text->find_last_not_of(std::string(" \0", 2)) + 1);
    series.push_back(s);
  }
  return series;
}

// "id (N files, 'description'), ..." for a message.
std::string series_list(const std::vector<DicomSeries>& series) {
  std::string text;
  for (const DicomSeries& s : series)
    text += (text.empty() ? "" : ", ") + s.uid + " (" + std::to_string(s.files) + " files" +
            (s.description.empty() ? "" : ", '" + s.description + "'") + ")";
  return text;
}

// The id of the series `wanted` names: by its Series Instance UID, or its id.
std::string chosen_series(const std::string& dir, const std::vector<DicomSeries>& series, const std::string& wanted) {
  if (series.empty())
    throw InputError("folder '" + dir + "' holds no DICOM series; give an image file or a DICOM folder");
  if (wanted.empty()) {
    if (series.size() == 1) return series.front().id;
    throw InputError("folder '" + dir + "' holds " + std::to_string(series.size()) +
                     " DICOM series; choose one by its Series Instance UID (segment --series, build-model "
                     "--labels-series or --image-series): " +
                     series_list(series));
  }
  std::vector<std::string> matches;
  for (const DicomSeries& s : series)
    if (s.uid == wanted || s.id == wanted) matches.push_back(s.id);
  if (matches.size() == 1) return matches.front();
  throw InputError("folder '" + dir + "' has " +
                   (matches.empty() ? "no DICOM series '" + wanted + "'"
                                    : std::to_string(matches.size()) + " series of UID '" + wanted +
                                          "' (of other sizes or orientations)") +
                   "; its series: " + series_list(series));
}

Volume read_dicom_series(const std::string& dir, const std::string& wanted) {
  auto names = series_names(dir);
  const std::string id = chosen_series(dir, series_of(names), wanted);
  auto reader = itk::ImageSeriesReader<FloatImage>::New();
  reader->SetImageIO(itk::GDCMImageIO::New());
  reader->SetFileNames(names->GetFileNames(id));
  reader->Update();
  return to_volume(reader->GetOutput(), dir);
}

// A single file through ITK's readers, after checks that name what is wrong.
Volume read_with_itk(const std::string& path) {
  const VoxelFile voxels = voxel_file(path);
  check_voxel_file_exists(path, voxels);
  auto io = itk::ImageIOFactory::CreateImageIO(path.c_str(), itk::ImageIOFactory::IOFileModeEnum::ReadMode);
  if (!io)
    throw InputError("'" + path +
                     "' is not an image format mrsnake reads (.nii .nii.gz .nrrd .mha .mhd .gipl, or a DICOM folder)");
  io->SetFileName(path);
  io->ReadImageInformation();
  const unsigned dims = io->GetNumberOfDimensions();
  if (dims != 3) {
    // NIfTI stores 3D images with trailing singleton dimensions as 4D; accept those.
    bool singleton_tail = dims > 3;
    for (unsigned d = 3; d < dims; ++d) singleton_tail = singleton_tail && io->GetDimensions(d) == 1;
    if (!singleton_tail)
      throw InputError("'" + path + "' is a " + std::to_string(dims) + "D image; mrsnake needs a 3D volume");
  }
  if (io->GetNumberOfComponents() != 1)
    throw InputError("'" + path + "' has " + std::to_string(io->GetNumberOfComponents()) +
                     " components per voxel; mrsnake needs a scalar image");
  check_size(voxels, io);
  auto reader = itk::ImageFileReader<FloatImage>::New();
  reader->SetFileName(path);
  reader->SetImageIO(io);
  reader->Update();
  return to_volume(reader->GetOutput(), path);
}

}  // namespace

std::vector<DicomSeries> list_dicom_series(const std::string& dir) {
  register_image_io();
  try {
    auto names = series_names(dir);
    return series_of(names);
  } catch (const itk::ExceptionObject& e) {
    throw InputError("cannot read the DICOM folder '" + dir + "': " + one_line_itk_error(e.GetDescription()));
  }
}

Volume read_volume(const std::string& path, const std::string& series) {
  register_image_io();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError("image '" + path + "' does not exist; check the path");
  try {
    if (std::filesystem::is_directory(path, ec)) return read_dicom_series(path, series);
    if (!series.empty())
      throw InputError("--series '" + series + "' names a DICOM series, but '" + path +
                       "' is a file, not a DICOM folder; give the folder, or no --series");
    // The completeness check decompresses the whole stream once more: it runs on the other
    // core while ITK reads (segment's load of a 256³ float .nii.gz: 1.07 -> 0.65 s). A truncated
    // stream is the clearer message, so its error wins over ITK's.
    Volume volume;
    run_both_in_parallel([&] { check_gzip_complete(path); }, [&] { volume = read_with_itk(path); });
    return volume;
  } catch (const itk::ExceptionObject& e) {
    throw InputError("cannot read image '" + path + "': " + one_line_itk_error(e.GetDescription()) +
                     "; the file may be corrupt or truncated");
  }
}

void write_volume(const std::string& path, const Volume& volume, VoxelType type) {
  write_volume(path, volume, type, {});
}

void write_volume(const std::string& path, const Volume& volume, VoxelType type,
                  const std::vector<std::pair<std::string, std::string>>& fields) {
  register_image_io();
  if (volume.data.size() != volume.num_voxels()) throw OutputError("internal: volume buffer does not match its size");
  auto image = FloatImage::New();
  FloatImage::RegionType region;
  FloatImage::SpacingType spacing;
  FloatImage::PointType origin;
  FloatImage::DirectionType direction;
  for (int d = 0; d < 3; ++d) {
    region.SetSize(d, volume.size[d]);
    spacing[d] = volume.spacing[d];
    origin[d] = volume.origin[d];
    for (int c = 0; c < 3; ++c) direction(d, c) = volume.direction[3 * d + c];
  }
  image->SetRegions(region);
  image->SetSpacing(spacing);
  image->SetOrigin(origin);
  image->SetDirection(direction);
  image->Allocate();
  std::copy(volume.data.begin(), volume.data.end(), image->GetBufferPointer());

  AtomicOutput out(path);
  try {
    auto write_as = [&](auto pixel) {
      using Pixel = decltype(pixel);
      using OutImage = itk::Image<Pixel, 3>;
      auto cast = OutImage::New();
      cast->CopyInformation(image);
      cast->SetRegions(region);
      cast->Allocate();
      const float* src = image->GetBufferPointer();
      Pixel* dst = cast->GetBufferPointer();
      for (std::size_t i = 0; i < volume.num_voxels(); ++i) dst[i] = static_cast<Pixel>(src[i]);
      for (const auto& [key, value] : fields)
        itk::EncapsulateMetaData<std::string>(cast->GetMetaDataDictionary(), key, value);
      auto writer = itk::ImageFileWriter<OutImage>::New();
      writer->SetFileName(out.temp_path());
      writer->SetInput(cast);
      writer->SetUseCompression(true);
      writer->Update();
    };
    switch (type) {
      case VoxelType::uint8: write_as(std::uint8_t{}); break;
      case VoxelType::int16: write_as(std::int16_t{}); break;
      case VoxelType::float32: write_as(float{}); break;
    }
  } catch (const itk::ExceptionObject& e) {
    throw OutputError("cannot write image '" + path + "': " + std::string(e.GetDescription()));
  }
  out.commit();
}

}  // namespace mrsnake
