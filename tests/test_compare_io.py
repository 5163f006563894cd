"""Backbone distance and CSV reading (binding and I/O surface)."""

import numpy as np
import pytest

from softrod import ParameterError, PlanarCableArm, backbone_distance, read_backbone_csv


def test_distance_of_a_backbone_to_itself_resampled_is_tiny():
    sol = PlanarCableArm.published_arm().solve(2.0, 401)
    fine = np.column_stack((sol.x, sol.y))
    coarse = fine[::8]  # 51 points, as if digitised
    d = backbone_distance(fine, coarse)
    assert d.max < 2e-4  # chord error of the coarse polyline, metres
    worst, mean = d  # unpacks as (max, mean)
    assert worst == d.max and mean == d.mean
    assert d.index.shape == d.distance.shape == (401,)


def test_distance_between_tensions_is_largest_at_the_tip():
    arm = PlanarCableArm.published_arm()
    a, b = arm.solve(1.0), arm.solve(1.2)
    d = backbone_distance(np.column_stack((a.x, a.y)), np.column_stack((b.x, b.y)), n_index=101)
    assert d.argmax_index == 1.0
    assert d.max == pytest.approx(np.hypot(*(a.tip - b.tip)))


def test_distance_rejects_bad_shapes():
    with pytest.raises(ParameterError):
        backbone_distance(np.zeros((5, 4)), np.zeros((5, 2)))
    with pytest.raises(ParameterError):
        backbone_distance([[0, 0]], [[0, 0], [1, 1]])
    with pytest.raises(ParameterError):
        backbone_distance([[0, 0], [1, 1]], [[0, 0, 0], [1, 1, 1]])


def test_read_backbone_csv_with_header_and_millimetres(tmp_path):
    f = tmp_path / "photo.csv"
    f.write_text("# digitised from photo 3\nx_mm,y_mm\n0,0\n100,5\n200,30\n260,80\n")
    pts = read_backbone_csv(f, scale=1e-3)
    np.testing.assert_allclose(pts[-1], [0.26, 0.08])
    assert pts.shape == (4, 2)


def test_read_backbone_csv_semicolons_and_whitespace(tmp_path):
    f = tmp_path / "a.csv"
    f.write_text("0;0\n1;2\n2;3\n")
    assert read_backbone_csv(f).shape == (3, 2)
    g = tmp_path / "b.txt"
    g.write_text("0 0 0\n1 2 3\n")
    assert read_backbone_csv(g).shape == (2, 3)


def test_read_backbone_csv_errors(tmp_path):
    f = tmp_path / "bad.csv"
    f.write_text("x,y\n0,0\n1,abc\n")
    with pytest.raises(ParameterError):
        read_backbone_csv(f)
    with pytest.raises(ParameterError):
        read_backbone_csv(f, scale=-1)


@pytest.mark.parametrize("text", ["", "# only a comment\n", "x,y,z\n", "keep\n"])
def test_read_backbone_csv_without_data_rows_names_the_path(tmp_path, text):
    f = tmp_path / "hdr.csv"
    f.write_text(text)
    with pytest.raises(ParameterError, match="no data rows") as info:
        read_backbone_csv(f)
    assert info.value.parameter == "path" and str(f) in str(info.value)


def test_read_backbone_csv_too_few_columns_names_the_file_and_its_columns(tmp_path):
    f = tmp_path / "one.csv"
    f.write_text("0\n1\n2\n")
    with pytest.raises(ParameterError) as info:
        read_backbone_csv(f)  # the default columns: a content error of the file
    text = str(info.value)
    assert info.value.parameter == "path" and str(f) in text and "1 column" in text
    g = tmp_path / "two.csv"
    g.write_text("x,y\n0,0\n1,2\n")
    with pytest.raises(ParameterError) as info:
        read_backbone_csv(g, columns=(0, 1, 2))  # the caller's columns: named, with the file's
    text = str(info.value)
    assert info.value.parameter == "columns" and "[0, 1, 2]" in text
    assert str(g) in text and "has 2 columns" in text
    np.testing.assert_array_equal(read_backbone_csv(g, columns=(1, 0)), [[0, 0], [2, 1]])
