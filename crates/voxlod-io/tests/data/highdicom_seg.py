"""A DICOM Segmentation written by highdicom (an independent writer) for the SEG reader's
test: a shuffled oblique CT series of 45x37 pixels made with pydicom as the source, a ball
(segment 1) and a box (segment 2) that touch, BINARY or FRACTIONAL (argv[2] == "fractional").
Prints per label the voxels and world centroid the reader must find, the overlap and the frame
count and BitsAllocated highdicom wrote."""
import sys, numpy as np, pydicom, highdicom as hd
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian, generate_uid, CTImageStorage
out = sys.argv[1]; frac = len(sys.argv) > 2 and sys.argv[2] == "fractional"
rows, cols, n = 37, 45, 30
dx, dy, step = 0.9, 1.1, 1.5
a, b = 0.5, 0.3
row = np.array([np.cos(a), np.sin(a), 0.0]); col = np.array([-np.sin(a)*np.cos(b), np.cos(a)*np.cos(b), np.sin(b)])
normal = np.cross(row, col)
origin = np.array([-20.0, -18.0, -22.0])
study, series, frame_uid = generate_uid(), generate_uid(), generate_uid()
ct = []
for k in range(n):
    ds = Dataset(); ds.file_meta = FileMetaDataset(); ds.file_meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds.SOPClassUID = CTImageStorage; ds.SOPInstanceUID = generate_uid(); ds.file_meta.MediaStorageSOPClassUID = ds.SOPClassUID
    ds.file_meta.MediaStorageSOPInstanceUID = ds.SOPInstanceUID
    ds.StudyInstanceUID = study; ds.SeriesInstanceUID = series; ds.FrameOfReferenceUID = frame_uid
    ds.PatientID = "P"; ds.PatientName = "Phantom^Test"; ds.PatientBirthDate = ""; ds.PatientSex = "O"
    ds.StudyDate = "20260101"; ds.StudyTime = "000000"; ds.AccessionNumber = ""; ds.ReferringPhysicianName = ""; ds.StudyID = "1"
    ds.Modality = "CT"; ds.SeriesNumber = 1; ds.InstanceNumber = k + 1
    ds.ImagePositionPatient = [float(v) for v in origin + normal * step * k]
    ds.ImageOrientationPatient = [float(v) for v in list(row) + list(col)]
    ds.PixelSpacing = [dy, dx]; ds.SliceThickness = step
    ds.Rows, ds.Columns = rows, cols; ds.SamplesPerPixel = 1; ds.PhotometricInterpretation = "MONOCHROME2"
    ds.BitsAllocated = 16; ds.BitsStored = 16; ds.HighBit = 15; ds.PixelRepresentation = 0
    ds.PixelData = np.zeros((rows, cols), np.uint16).tobytes()
    ct.append(ds)
# World position of every pixel, then a ball (segment 1) and a box (segment 2) that touch.
r, c = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
mask = np.zeros((n, rows, cols, 2), bool)
ball_c, ball_r = np.array([-3.0, 1.0, 0.0]), 7.0
box_lo, box_hi = np.array([3.5, -4.0, -4.0]), np.array([12.0, 4.0, 3.0])
for k in range(n):
    p = origin + normal * step * k
    w = p[None, None, :] + c[..., None] * dx * row + r[..., None] * dy * col
    mask[k, :, :, 0] = np.linalg.norm(w - ball_c, axis=-1) <= ball_r
    mask[k, :, :, 1] = np.all((w >= box_lo) & (w <= box_hi), axis=-1)
# Shuffle the source images: highdicom sorts nothing we rely on.
order = np.random.default_rng(3).permutation(n)
ct = [ct[i] for i in order]; mask = mask[order]
cat = hd.sr.CodedConcept("91723000", "SCT", "Anatomical Structure")
prop = hd.sr.CodedConcept("85756007", "SCT", "Tissue")
segs = [hd.seg.SegmentDescription(segment_number=i + 1, segment_label=name, segmented_property_category=cat,
        segmented_property_type=prop, algorithm_type=hd.seg.SegmentAlgorithmTypeValues.MANUAL,
        display_color=hd.color.CIELabColor(*lab))
        for i, (name, lab) in enumerate([("ball", (53.24, 80.09, 67.20)), ("box", (87.73, -86.18, 83.18))])]
kind = hd.seg.SegmentationTypeValues.FRACTIONAL if frac else hd.seg.SegmentationTypeValues.BINARY
pixels = mask.astype(np.float32) if frac else mask
seg = hd.seg.Segmentation(source_images=ct, pixel_array=pixels, segmentation_type=kind,
    segment_descriptions=segs, series_instance_uid=generate_uid(), series_number=2,
    sop_instance_uid=generate_uid(), instance_number=1, manufacturer="voxlod tests",
    manufacturer_model_name="seg13", software_versions="0", device_serial_number="1",
    max_fractional_value=255 if frac else None)
seg.save_as(out)
# What the reader must paint: every voxel of each segment, the box (the later segment number)
# where both are; centroids in world coordinates (LPS), from the unshuffled plane index.
label = np.where(mask[..., 1], 2, np.where(mask[..., 0], 1, 0))
for s in (1, 2):
    idx = np.argwhere(label == s)
    ks = order[idx[:, 0]]
    w = origin + normal * step * ks[:, None] + idx[:, 2:3] * dx * row + idx[:, 1:2] * dy * col
    cen = w.mean(axis=0)
    print(s, len(idx), f"{cen[0]:.6f} {cen[1]:.6f} {cen[2]:.6f}")
print("overlap", int((mask[..., 0] & mask[..., 1]).sum()))
print("frames", int(seg.NumberOfFrames), int(seg.BitsAllocated))
