/* placeholder: being written this session */
typedef int tt_placeholder_io_gdal_write;
