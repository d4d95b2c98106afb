#include "tests/support/dicom_series_itk.h"

#include <itkGDCMImageIO.h>
#include <itkImage.h>
#include <itkImageSeriesWriter.h>
#include <itkMetaDataObject.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "mesh/itk_volume.h"

namespace mrsnake::test {
namespace {

using Image3 = itk::Image<short, 3>;
using Image2 = itk::Image<short, 2>;

std::string numbers(const std::vector<double>& values) {
  std::string text;
  char one[32];
  for (const double v : values) {
    std::snprintf(one, sizeof one, "%.6f", v);
    text += (text.empty() ? "" : "\\") + std::string(one);
  }
  return text;
}

Image3::Pointer to_itk(const Volume& volume) {
  auto image = itk_volume::allocate_like<Image3>(volume);
  for (std::size_t i = 0; i < volume.num_voxels(); ++i)
    image->GetBufferPointer()[i] = static_cast<short>(std::lround(volume.data[i]));
  return image;
}

}  // namespace

void write_dicom_series(const std::string& dir, const std::string& prefix, const Volume& volume,
                        const std::string& series_uid, const std::string& description) {
  const Image3::Pointer image = to_itk(volume);
  std::vector<itk::MetaDataDictionary> slices(volume.size[2]);
  std::vector<std::string> names;
  const auto& d = volume.direction;
  for (std::size_t k = 0; k < volume.size[2]; ++k) {
    const auto position = volume.index_to_physical(0, 0, static_cast<double>(k));
    itk::MetaDataDictionary& tags = slices[k];
    const auto set = [&](const char* tag, const std::string& value) {
      itk::EncapsulateMetaData<std::string>(tags, tag, value);
    };
    set("0008|0060", "MR");
    set("0008|0016", "1.2.840.10008.5.1.4.1.1.4");  // MR Image Storage
    set("0020|000d", "1.2.826.0.1.3680043.2.1125.1");
    set("0020|000e", series_uid);
    set("0008|0018", series_uid + "." + std::to_string(k + 1));
    set("0008|103e", description);
    set("0020|0013", std::to_string(k + 1));
    set("0020|0032", numbers({position[0], position[1], position[2]}));
    set("0020|0037", numbers({d[0], d[3], d[6], d[1], d[4], d[7]}));
    set("0028|0030", numbers({volume.spacing[1], volume.spacing[0]}));
    set("0018|0050", numbers({volume.spacing[2]}));
    char name[64];
    std::snprintf(name, sizeof name, "%s_%03zu.dcm", prefix.c_str(), k + 1);
    names.push_back(dir + "/" + name);
  }
  auto io = itk::GDCMImageIO::New();
  io->KeepOriginalUIDOn();
  auto writer = itk::ImageSeriesWriter<Image3, Image2>::New();
  writer->SetInput(image);
  writer->SetImageIO(io);
  writer->SetFileNames(names);
  std::vector<itk::MetaDataDictionary*> slice_tags;
  for (itk::MetaDataDictionary& tags : slices) slice_tags.push_back(&tags);
  writer->SetMetaDataDictionaryArray(&slice_tags);
  try {
    writer->Update();
  } catch (const itk::ExceptionObject& e) {
    throw std::runtime_error(std::string("writing the DICOM series failed: ") + e.GetDescription());
  }
}

}  // namespace mrsnake::test
