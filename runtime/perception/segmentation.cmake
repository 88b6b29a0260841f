# Semantic segmentation of camera frames: an ONNX network run by OpenCV's dnn module on the CPU.
# OpenCV stays out of the header, so users link only autoshovel_sensors' types.
add_library(autoshovel_segmentation ${CMAKE_CURRENT_LIST_DIR}/segmentation.cc)
target_link_libraries(autoshovel_segmentation PUBLIC autoshovel_sensors
                                              PRIVATE opencv_core opencv_imgproc opencv_dnn)
autoshovel_target_warnings(autoshovel_segmentation)
