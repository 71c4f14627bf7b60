@echo off
rem Registers SDF Autograsp as an implicit OpenXR API layer: every 64-bit OpenXR app then loads
rem it (docs/windows.md). Run it from the folder that holds XrApiLayer_sdfg_autograsp.dll and
rem XrApiLayer_sdfg_autograsp.json; the loader reads the manifest from there, so keep the folder.
rem   install-layer.bat          all users (HKLM; run from an administrator's prompt)
rem   install-layer.bat /user    this user only (HKCU; no administrator needed)
rem Undo with uninstall-layer.bat (same argument).
setlocal
set "ARG=%~1"
set "ROOT=HKLM"
if not defined ARG goto args_ok
set "ROOT=HKCU"
if /i "%ARG%"=="/user" goto args_ok
echo install-layer: unknown argument "%ARG%" (use /user or nothing)
exit /b 2
:args_ok
set "MANIFEST=%~dp0XrApiLayer_sdfg_autograsp.json"
if not exist "%MANIFEST%" (
  echo install-layer: no XrApiLayer_sdfg_autograsp.json beside this script
  exit /b 1
)
if not exist "%~dp0XrApiLayer_sdfg_autograsp.dll" (
  echo install-layer: no XrApiLayer_sdfg_autograsp.dll beside this script
  exit /b 1
)
rem One DWORD value per manifest path; 0 means enabled.
reg add "%ROOT%\SOFTWARE\Khronos\OpenXR\1\ApiLayers\Implicit" /v "%MANIFEST%" /t REG_DWORD /d 0 /f >nul
if errorlevel 1 (
  echo install-layer: could not write %ROOT%: run it as administrator, or with /user
  exit /b 1
)
echo install-layer: registered %MANIFEST% under %ROOT%\SOFTWARE\Khronos\OpenXR\1\ApiLayers\Implicit
echo install-layer: set DISABLE_XR_APILAYER_SDFG_AUTOGRASP=1 to turn it off for one app
exit /b 0
